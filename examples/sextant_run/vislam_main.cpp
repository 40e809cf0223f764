// sextant-vislam: seed 004's visual-inertial SLAM on SE(3) (IMU velocities, stereo pixel pairs) on
// KITTI-derived .npz files and on the simulated stereo car, every back-end against dead reckoning.
// It takes sextant-run's options (sextant-run --dataset FILE.npz | stereo-vi hands over to it); see
// docs/runner.md.
#include "runner_cli.hpp"
#include "vislam_runs.hpp"

int main(int argc, char** argv) {
  using namespace sextant::runner;
  return runner_main(argc, argv, "sextant-vislam",
                     "sextant-vislam: visual-inertial SLAM on SE(3) on .npz stereo+IMU data or the simulated stereo car",
                     [](CliOptions& options) {
                       if (options.datasets.empty()) options.datasets = {"stereo-vi"};
                       for (const auto& dataset : options.datasets)
                         if (!is_vislam_dataset(dataset))
                           throw sextant::invalid_input_error("--dataset " + dataset +
                                                              ": sextant-vislam runs stereo-vi and .npz files (sextant-run runs the rest)");
                       const RunnerConfig config = load_runner_config(options);
                       const auto kinds = parse_backends(options.backends);
                       std::vector<TableRow> rows;
                       for (const auto& dataset : options.datasets) {
                         auto part = run_vislam(options.output, dataset, kinds, config);
                         rows.insert(rows.end(), part.begin(), part.end());
                       }
                       finish_run(options, rows);
                       return 0;
                     });
}
