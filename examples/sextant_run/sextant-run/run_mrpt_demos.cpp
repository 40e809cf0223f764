// sextant-run's mrpt-demos family: the kf-slam demo rawlogs that Debian's mrpt-common installs, each
// as a rawlog (run_planar_rawlog.cpp).
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "dataset_registry.hpp"
#include "landmark_dataset_runs.hpp"

namespace sextant::runner {
namespace {

const char* const kMrptDatasets = "/usr/share/mrpt/datasets";
const char* const kMrptDemos[] = {"kf-slam_demo.rawlog", "kf-slam_6D_demo.rawlog", "kf-slam_6D_demo_noncentered.rawlog"};

/// Every installed demo rawlog; a missing one is a note, not an error.
std::vector<TableRow> run_mrpt_demos(const CliOptions& cli, const std::string&, const std::vector<BackendKind>& kinds,
                                     const RunnerConfig& config) {
  std::vector<TableRow> rows;
  for (const char* demo : kMrptDemos) {
    const auto path = std::string(kMrptDatasets) + "/" + demo;
    if (!std::filesystem::exists(path)) {
      std::printf("note: %s not found (Debian package mrpt-common), skipped\n", path.c_str());
      continue;
    }
    auto part = run_rawlog(cli, path, kinds, config);
    rows.insert(rows.end(), part.begin(), part.end());
  }
  return rows;
}

const RegisterDatasetRun registration{"mrpt-demos", run_mrpt_demos};

}  // namespace
}  // namespace sextant::runner
