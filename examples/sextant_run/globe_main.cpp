// sextant-globe: the thesis's visual SLAM experiment (seed 000, §4.2.2, §5.2): the 12D Euler-angle
// camera circling a simulated globe, every back-end through the bounded landmark pool. It takes
// sextant-run's options (sextant-run --dataset globe hands over to it); see docs/runner.md.
#include "runner_cli.hpp"

using namespace sextant::runner;

int main(int argc, char** argv) {
  return family_main(
      argc, argv, "sextant-globe",
      "sextant-globe: the thesis's 12D camera around a simulated globe, every back-end through the landmark pool",
      is_globe_dataset, "only the globe",
      [](const CliOptions& options, const std::string&, const std::vector<BackendKind>& kinds,
         const RunnerConfig& config) { return run_globe(options.output, kinds, config); },
      {"globe"});
}
