// sextant-run-mrclam: every back-end on the UTIAS MRCLAM robots, scored against Vicon. It takes
// sextant-run's options (sextant-run --dataset mrclam:<dir>:<robot> hands over to it, so that the
// main job does not compile it); see docs/runner.md.
#include "runner_cli.hpp"

using namespace sextant::runner;

int main(int argc, char** argv) {
  return family_main(
      argc, argv, "sextant-run-mrclam", "sextant-run-mrclam: SLAM back-ends on the UTIAS MRCLAM robots against Vicon",
      is_mrclam_dataset, "mrclam:<dir>:<robot 1-5|all>",
      [](const CliOptions& options, const std::string& dataset, const std::vector<BackendKind>& kinds,
         const RunnerConfig& config) { return run_mrclam(options.output, dataset.substr(7), kinds, config); });
}
