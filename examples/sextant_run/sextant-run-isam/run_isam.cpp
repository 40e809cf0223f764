// sextant-run's iSAM part: every chosen back-end, filters included, on a planar data set in the
// iSAM/GTSAM text format (--dataset <file.txt>: cityTrees10000, Victoria Park); scored when a
// noise-free <name>_groundtruth.txt lies beside it, otherwise timed and written out only. The
// filters run in the world chart ([isam] filters_in_world_frame, planar_world_frame_runs.hpp).
#include <filesystem>
#include <sextant/io/isam_dataset.hpp>

#include "dataset_registry.hpp"
#include "dataset_runner.hpp"
#include "planar_world_frame_runs.hpp"

namespace sextant::runner {

namespace {

std::vector<TableRow> run_isam(const CliOptions& cli, const std::string& path, const std::vector<BackendKind>& kinds,
                               const RunnerConfig& settings) {
  RunnerConfig config = settings;
  config.graph.window = settings.isam_graph_window;
  const auto data = io::read_isam_dataset(path);
  std::size_t sightings = 0;
  for (const auto& step : data.steps) sightings += step.observations.size();
  std::printf("\n%s: %zu steps, %zu landmark sightings%s\n", path.c_str(), data.steps.size(), sightings,
              data.has_ground_truth() ? "" : "; no ground truth beside it: the runs are timed and written out, not scored");
  print_warnings(data.implausible);
  if (config.graph.window > 0)
    std::printf("GraphSLAM starts from a windowed initialization of %zu steps ([isam] graph_window)\n", config.graph.window);
  if (config.isam_filters_in_world_frame)
    std::printf("EKF, SEIF and ESEIF perturb the pose in the world frame ([isam] filters_in_world_frame), where "
                "first-estimate Jacobians keep the global heading unobservable\n");
  const std::string name = std::filesystem::path(path).filename().string();
  print_dataset_header(name, data, "m");
  return run_rows_with_filters_in_world_frame(cli.output, name, data, kinds, config, config.isam_filters_in_world_frame, "m");
}

const RegisterDatasetRun registration{"isam", run_isam};

}  // namespace
}  // namespace sextant::runner
