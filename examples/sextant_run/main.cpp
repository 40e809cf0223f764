// sextant-run: every back-end on the simulated ship and on MRPT rawlogs, scored against ground
// truth, side by side. With no arguments: all back-ends on the ship Monte Carlo and on the kf-slam
// demo rawlogs that Debian's mrpt-common installs. The other data-set families run in programs of
// their own, so that the main job does not compile them, and sextant-run hands them over
// (kHandOvers): --dataset globe to sextant-globe (the thesis's 12D camera around a simulated globe),
// stereo-vi or FILE.npz to sextant-vislam (visual-inertial SLAM on SE(3)), globe-stereo or
// stereo:<dir> to sextant-globe-stereo (stereo images through the OpenCV front-end),
// mrclam:<dir>:<robot> to sextant-run-mrclam, FILE.txt (iSAM text) to sextant-run-isam.
// See docs/runner.md.
#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <unistd.h>
#include <vector>

#include "runner_cli.hpp"
#include "sextant/core/error.hpp"

namespace {

using namespace sextant;
using namespace sextant::runner;

const char* const kMrptDatasets = "/usr/share/mrpt/datasets";
const std::vector<std::string> kMrptDemos = {"kf-slam_demo.rawlog", "kf-slam_6D_demo.rawlog",
                                             "kf-slam_6D_demo_noncentered.rawlog"};

/// The installed demo rawlogs in place of "mrpt-demos", each that exists.
std::vector<std::string> expand_datasets(const std::vector<std::string>& requested) {
  std::vector<std::string> out;
  for (const auto& d : requested) {
    if (d != "mrpt-demos") {
      out.push_back(d);
      continue;
    }
    for (const auto& demo : kMrptDemos) {
      const auto path = std::string(kMrptDatasets) + "/" + demo;
      if (std::filesystem::exists(path)) out.push_back(path);
      else std::printf("note: %s not found (Debian package mrpt-common), skipped\n", path.c_str());
    }
  }
  return out;
}

/// sextant-run's own data sets: the ship, the demo rawlogs, a rawlog; the other families' go to their
/// programs (kHandOvers) before this is asked.
bool is_main_dataset(const std::string&) { return true; }

std::vector<TableRow> run_main_dataset(const CliOptions& options, const std::string& dataset,
                                       const std::vector<BackendKind>& kinds, const RunnerConfig& config) {
  if (dataset == "ship") return run_ship(options.output, kinds, config);
  return run_rawlog(options.output, dataset, kinds, config);
}

/// A family of data sets that runs in a program of its own next to sextant-run.
struct HandOver {
  bool (*is_its)(const std::string&);
  const char* what;  ///< the family, for messages
  const char* program;
};
const HandOver kHandOvers[] = {
    {is_stereo_image_dataset, "globe-stereo and stereo:<dir>", "sextant-globe-stereo"},
    {is_globe_dataset, "globe", "sextant-globe"},
    {is_vislam_dataset, "stereo-vi and .npz files", "sextant-vislam"},
    {is_mrclam_dataset, "mrclam:<dir>:<robot>", "sextant-run-mrclam"},
    {is_isam_dataset, ".txt and .graph files (iSAM text)", "sextant-run-isam"},
};

/// Whether the data sets are `program`'s (is_its): they run there alone, all of them in one call,
/// so a mixture with the others is an error. `what` names them for the message.
bool wants(const CliOptions& options, bool (*is_its)(const std::string&), const char* what, const char* program) {
  const auto& d = options.datasets;
  const auto count = std::count_if(d.begin(), d.end(), is_its);
  if (count == 0) return false;
  if (static_cast<std::size_t>(count) != d.size())
    throw invalid_input_error(std::string("--dataset ") + what + ": runs alone (in the program " + program +
                              "); give the other data sets in a second call");
  return true;
}

/// Replaces this process by `program` (next to it) with the same arguments.
int hand_over_to(const char* program, char** argv) {
  const auto path = std::filesystem::canonical("/proc/self/exe").parent_path() / program;
  std::fflush(stdout);
  ::execv(path.c_str(), argv);
  std::fprintf(stderr, "sextant-run: cannot start %s (%s): build it with cmake --build <build> --target %s, or "
               "run ./run.sh main with the same --dataset\n", path.c_str(), std::strerror(errno), program);
  return 1;
}

}  // namespace

int main(int argc, char** argv) {
  return runner_main(argc, argv, "sextant-run",
                     "sextant-run: SLAM back-ends on the simulated ship and on MRPT rawlogs, side by side",
                     [argv](CliOptions& options) {
                       for (const auto& family : kHandOvers)
                         if (wants(options, family.is_its, family.what, family.program))
                           return hand_over_to(family.program, argv);
                       return run_datasets(options, "sextant-run", is_main_dataset, "the ship and rawlogs",
                                           run_main_dataset, {"ship", "mrpt-demos"}, expand_datasets);
                     });
}
