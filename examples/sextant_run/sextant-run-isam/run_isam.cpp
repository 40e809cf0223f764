// sextant-run's iSAM part: every chosen back-end, filters included, on a planar data set in the
// iSAM/GTSAM text format (--dataset <file.txt>: cityTrees10000, Victoria Park); scored when a
// noise-free <name>_groundtruth.txt lies beside it, otherwise timed and written out only.
#include <filesystem>
#include <sextant/io/isam_dataset.hpp>

#include "dataset_registry.hpp"
#include "dataset_runner.hpp"

namespace sextant::runner {

namespace {

std::vector<TableRow> run_isam(const CliOptions& cli, const std::string& path, const std::vector<BackendKind>& kinds,
                               const RunnerConfig& config) {
  const auto data = io::read_isam_dataset(path);
  std::size_t sightings = 0;
  for (const auto& step : data.steps) sightings += step.observations.size();
  std::printf("\n%s: %zu steps, %zu landmark sightings%s\n", path.c_str(), data.steps.size(), sightings,
              data.has_ground_truth() ? "" : "; no ground truth beside it: the runs are timed and written out, not scored");
  print_warnings(data.implausible);
  return run_dataset(cli.output, std::filesystem::path(path).filename().string(), data, kinds, config, "m");
}

const RegisterDatasetRun registration{"isam", run_isam};

}  // namespace
}  // namespace sextant::runner
