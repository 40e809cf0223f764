// sextant-run's rawlog part: reading a rawlog with its ground truth, and every chosen back-end on a
// planar one (the spatial ones: run_spatial_rawlog.cpp).
#include <filesystem>
#include <sextant/mrpt/rawlog.hpp>
#include <variant>

#include "dataset_registry.hpp"
#include "dataset_runner.hpp"
#include "landmark_dataset_runs.hpp"

namespace sextant::runner {
namespace {

/// The ground-truth files beside a rawlog, which sextant-run needs to score the runs.
mrpt_io::GroundTruthFiles require_ground_truth(const std::string& path) {
  const auto truth = mrpt_io::find_ground_truth(path);
  if (!truth)
    throw parse_error(path + ": no ground truth beside it (<stem>_ground_truth.txt and "
                             "<stem>_ground_truth_robot_path.txt, or simul-landmarks' <name>.rawlog_ground_truth.txt "
                             "and <name>.rawlog_ground_truth_robot_path.txt); sextant-run scores against ground truth");
  return *truth;
}

}  // namespace

std::vector<TableRow> run_rawlog(const CliOptions& cli, const std::string& path, const std::vector<BackendKind>& kinds,
                                 const RunnerConfig& config) {
  const std::string name = std::filesystem::path(path).filename().string();
  auto dataset = mrpt_io::read_rawlog(path, config.rawlog);
  return std::visit(
      [&](auto& data) {
        mrpt_io::attach_ground_truth(data, require_ground_truth(path));
        return run_landmark_dataset(cli.output, name, data, kinds, config);
      },
      dataset);
}

const RegisterDatasetRun rawlog_registration{"rawlog", run_rawlog};

std::vector<TableRow> run_landmark_dataset(const RunOptions& options, const std::string& name,
                                           const io::LandmarkDataset<Se2Odometry, RangeBearing2D>& data,
                                           const std::vector<BackendKind>& kinds, const RunnerConfig& config) {
  return run_dataset(options, name, data, kinds, config, "m");
}

}  // namespace sextant::runner
