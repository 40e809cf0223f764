// sextant-run-isam: every back-end on a planar data set in the iSAM/GTSAM text format
// (cityTrees10000, Victoria Park), scored where its ground truth lies beside it. It takes
// sextant-run's options (sextant-run --dataset FILE.txt hands over to it, so that the main job does
// not compile it); see docs/runner.md.
#include "runner_cli.hpp"

using namespace sextant::runner;

int main(int argc, char** argv) {
  return family_main(
      argc, argv, "sextant-run-isam", "sextant-run-isam: SLAM back-ends on a planar iSAM/GTSAM text data set",
      is_isam_dataset, ".txt and .graph files (iSAM/GTSAM planar text)",
      [](const CliOptions& options, const std::string& dataset, const std::vector<BackendKind>& kinds,
         const RunnerConfig& config) { return run_isam(options.output, dataset, kinds, config); });
}
