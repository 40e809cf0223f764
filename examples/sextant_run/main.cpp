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
#include <variant>
#include <vector>

#include "rawlog_runs.hpp"
#include "runner_cli.hpp"

namespace {

using namespace sextant;
using namespace sextant::runner;

const char* const kMrptDatasets = "/usr/share/mrpt/datasets";
const std::vector<std::string> kMrptDemos = {"kf-slam_demo.rawlog", "kf-slam_6D_demo.rawlog",
                                             "kf-slam_6D_demo_noncentered.rawlog"};

/// "ship", "mrpt-demos" (the installed demo rawlogs) or a rawlog path, expanded.
std::vector<std::string> expand_datasets(const std::vector<std::string>& requested) {
  std::vector<std::string> out;
  for (const auto& d : requested.empty() ? std::vector<std::string>{"ship", "mrpt-demos"} : requested) {
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

/// The ground-truth files beside a rawlog, which sextant-run needs to score the runs.
mrpt_io::GroundTruthFiles require_ground_truth(const std::string& path) {
  const auto truth = mrpt_io::find_ground_truth(path);
  if (!truth)
    throw parse_error(path + ": no ground truth beside it (<name>_ground_truth.txt and "
                             "<name>_ground_truth_robot_path.txt); sextant-run scores against ground truth");
  return *truth;
}

/// A rawlog with the MRPT ground-truth files beside it, as planar or spatial.
std::vector<TableRow> run_rawlog(const CliOptions& options, const std::string& path, const std::vector<BackendKind>& kinds,
                                 const RunnerConfig& config) {
  const std::string name = std::filesystem::path(path).filename().string();
  auto dataset = mrpt_io::read_rawlog(path, config.rawlog);
  return std::visit(
      [&](auto& data) {
        mrpt_io::attach_ground_truth(data, require_ground_truth(path));
        return run_rawlog_dataset(options.output, name, data, kinds, config);
      },
      dataset);
}

bool is_globe_dataset(const std::string& dataset) { return dataset == "globe"; }

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
                       const RunnerConfig config = load_runner_config(options);
                       const auto kinds = parse_backends(options.backends);
                       std::vector<TableRow> rows;
                       for (const auto& dataset : expand_datasets(options.datasets)) {
                         auto part = dataset == "ship" ? run_ship(options.output, kinds, config)
                                                       : run_rawlog(options, dataset, kinds, config);
                         rows.insert(rows.end(), part.begin(), part.end());
                       }
                       finish_run(options, rows);
                       return 0;
                     });
}
