#pragma once
// The planar filters in the world chart (models/se2_world_frame.hpp), for every planar data set
// whose robot moves on Se2Space (MRCLAM, the iSAM text files): EKF, SEIF and ESEIF run with the pose
// perturbed in the world frame, where first-estimate Jacobians (on there by default, "auto") keep
// the global pose unobservable; GraphSLAM and FastSLAM keep the additive chart. Only the filters,
// which linearize once: GraphSLAM's Gauss-Newton steps in this chart turn far poses about the
// origin, and from dead reckoning it diverges (docs/derivations/se2_world_frame.md).
#include <string>
#include <utility>
#include <vector>

#include <sextant/io/landmark_dataset.hpp>
#include <sextant/models/se2_world_frame.hpp>

#include "dataset_runner.hpp"

namespace sextant::runner {

/// The same data with the motion and sensor models wrapped for the world chart and the prior
/// expressed in it; the steps and the ground truth unchanged.
template <class Dataset>
io::LandmarkDataset<InWorldFrame<typename Dataset::Motion>, SeenInWorldFrame<typename Dataset::Sensor>> in_world_frame(
    const Dataset& data) {
  io::LandmarkDataset<InWorldFrame<typename Dataset::Motion>, SeenInWorldFrame<typename Dataset::Sensor>> out;
  out.path = data.path;
  out.motion = InWorldFrame<typename Dataset::Motion>(data.motion);
  out.sensor = SeenInWorldFrame<typename Dataset::Sensor>(data.sensor);
  out.prior = sextant::in_world_frame(data.prior);
  out.steps = data.steps;
  out.true_poses = data.true_poses;
  out.true_landmarks = data.true_landmarks;
  out.ids = data.ids;
  return out;
}

/// The chosen back-ends split into those run in the world chart (EKF, SEIF and ESEIF, if `world`) and the rest.
inline std::pair<std::vector<BackendKind>, std::vector<BackendKind>> split_filters(const std::vector<BackendKind>& kinds,
                                                                                   bool world) {
  std::pair<std::vector<BackendKind>, std::vector<BackendKind>> out;
  for (const BackendKind kind : kinds)
    (world && (kind == BackendKind::ekf || kind == BackendKind::seif || kind == BackendKind::eseif) ? out.first : out.second)
        .push_back(kind);
  return out;
}

/// run_dataset_rows with the filters in the world chart if `filters_in_world_frame`: their rows
/// first, then the rest's; the plots are drawn once, after the last part that ran.
template <class Dataset>
std::vector<TableRow> run_rows_with_filters_in_world_frame(const RunOptions& options, const std::string& name,
                                                           const Dataset& data, const std::vector<BackendKind>& kinds,
                                                           const RunnerConfig& config, bool filters_in_world_frame,
                                                           const char* unit) {
  const auto [filters, others] = split_filters(kinds, filters_in_world_frame);
  RunOptions plot_once = options;
  plot_once.plots = options.plots && others.empty();
  auto rows = run_dataset_rows(plot_once, name, in_world_frame(data), filters, config, unit);
  const auto rest = run_dataset_rows(options, name, data, others, config, unit);
  rows.insert(rows.end(), rest.begin(), rest.end());
  return rows;
}

}  // namespace sextant::runner
