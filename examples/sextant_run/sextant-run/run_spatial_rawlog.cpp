// sextant-run's spatial rawlog part: every chosen back-end on one spatial MRPT rawlog.
#include "dataset_runner.hpp"
#include "landmark_dataset_runs.hpp"

namespace sextant::runner {

std::vector<TableRow> run_landmark_dataset(const RunOptions& options, const std::string& name,
                                           const io::LandmarkDataset<Se3Odometry, RangeBearing3D>& data,
                                           const std::vector<BackendKind>& kinds, const RunnerConfig& config) {
  return run_dataset(options, name, data, kinds, config, "m");
}

}  // namespace sextant::runner
