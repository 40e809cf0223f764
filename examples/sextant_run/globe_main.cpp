// sextant-globe: the thesis's visual SLAM experiment (seed 000, §4.2.2, §5.2): the 12D Euler-angle
// camera circling a simulated globe, every back-end through the bounded landmark pool. It takes
// sextant-run's options (sextant-run --dataset globe hands over to it); see docs/runner.md.
#include "runner_cli.hpp"

int main(int argc, char** argv) {
  using namespace sextant::runner;
  return runner_main(argc, argv, "sextant-globe",
                     "sextant-globe: the thesis's 12D camera around a simulated globe, every back-end through the "
                     "landmark pool",
                     [](CliOptions& options) {
                       for (const auto& dataset : options.datasets)
                         if (dataset != "globe")
                           throw sextant::invalid_input_error("--dataset " + dataset +
                                                              ": sextant-globe runs only the globe (sextant-run runs the rest)");
                       const RunnerConfig config = load_runner_config(options);
                       finish_run(options, run_globe(options.output, parse_backends(options.backends), config));
                       return 0;
                     });
}
