// sextant-vislam: seed 004's visual-inertial SLAM on SE(3) (IMU velocities, stereo pixel pairs) on
// KITTI-derived .npz files and on the simulated stereo car, every back-end against dead reckoning.
// It takes sextant-run's options (sextant-run --dataset FILE.npz | stereo-vi hands over to it); see
// docs/runner.md.
#include "runner_cli.hpp"
#include "vislam_runs.hpp"

using namespace sextant::runner;

int main(int argc, char** argv) {
  return family_main(
      argc, argv, "sextant-vislam",
      "sextant-vislam: visual-inertial SLAM on SE(3) on .npz stereo+IMU data or the simulated stereo car",
      is_vislam_dataset, "stereo-vi and .npz files",
      [](const CliOptions& options, const std::string& dataset, const std::vector<BackendKind>& kinds,
         const RunnerConfig& config) { return run_vislam(options.output, dataset, kinds, config); },
      {"stereo-vi"});
}
