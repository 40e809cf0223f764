#pragma once
// What sextant-run writes with --out: per data set and back-end a per-step CSV, the final map as
// CSV, TUM trajectories (estimate and ground truth), an MRPT .3Dscene; and a summary.json of the
// whole table.
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <limits>
#include <sstream>
#include <sextant/core/pose3_euler_space.hpp>
#include <sextant/eval/metrics.hpp>
#include <sextant/io/csv_writer.hpp>
#include <sextant/io/tum_writer.hpp>
#include <sextant/mrpt/scene.hpp>
#include <string>
#include <vector>

#include "experiments.hpp"

namespace sextant::runner {

/// A pose or position of any of the runner's state types as a point in 3D.
template <class State>
Eigen::Vector3d position_3d(const State& x) {
  if constexpr (State::RowsAtCompileTime == 6) return x.template head<3>();
  else return {x(0), x(1), 0.0};
}

/// A state as a TUM pose: positions (ship), planar poses (x, y, heading), 6D (x y z yaw pitch roll).
template <class State>
io::TumPose tum_pose(double timestamp, const State& x) {
  if constexpr (State::RowsAtCompileTime == 2) return io::tum_pose_from_position(timestamp, x);
  else if constexpr (State::RowsAtCompileTime == 3) return io::tum_pose_from_se2(timestamp, x(0), x(1), x(2));
  else return {timestamp, x.template head<3>(), Eigen::Quaterniond(rotation_from_ypr(x(3), x(4), x(5)))};
}

template <class Dataset>
void write_steps_csv(const std::string& path, const BackendRun<Dataset>& r) {
  constexpr Scoring scoring = scoring_of<Dataset>();
  std::vector<std::string> header{"step", "x", "y", "z", "pose_error", "pose_nees", "nees_bound_95", "seconds"};
  io::CsvWriter csv(path, header);
  const double bound = eval::nees_upper_bound(scoring.pose_dof, 0.95);
  const auto at = [](const std::vector<double>& v, std::size_t k) {  // NaN where unscored (no ground truth)
    return k < v.size() ? v[k] : std::numeric_limits<double>::quiet_NaN();
  };
  for (std::size_t k = 0; k < r.run.trajectory.size(); ++k) {
    const Eigen::Vector3d p = position_3d(r.run.trajectory[k]);
    csv.row({static_cast<double>(k + 1), p.x(), p.y(), p.z(), at(r.run.pose_error, k), at(r.run.pose_nees, k), bound,
             k < r.run.seconds.size() ? r.run.seconds[k] : 0.0});
  }
}

template <class Dataset>
void write_map_csv(const std::string& path, const BackendRun<Dataset>& r, const Dataset& data) {
  io::CsvWriter csv(path, {"id", "x", "y", "z", "true_x", "true_y", "true_z", "cov_xx", "cov_xy", "cov_yy"});
  for (const auto& l : r.map) {
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    Eigen::Vector3d truth = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());  // none known
    mean.head(l.mean.size()) = l.mean;
    const auto it = data.true_landmarks.find(l.id);
    if (it != data.true_landmarks.end()) {
      truth.setZero();
      truth.head(it->second.size()) = it->second;
    }
    csv.row({static_cast<double>(l.id), mean.x(), mean.y(), mean.z(), truth.x(), truth.y(), truth.z(), l.cov(0, 0),
             l.cov(0, 1), l.cov(1, 1)});
  }
}

template <class Dataset>
mrpt_io::SceneContent scene_content(const BackendRun<Dataset>& r, const Dataset& data) {
  mrpt_io::SceneContent scene;
  for (const auto& x : r.run.trajectory) scene.estimated_path.push_back(position_3d(x));
  for (std::size_t k = 1; k < data.true_poses.size() && k <= r.run.trajectory.size(); ++k)
    scene.true_path.push_back(position_3d(data.true_poses[k]));
  scene.landmarks = mrpt_io::scene_landmarks(r.map);
  for (const auto& [id, m] : data.true_landmarks) {
    Eigen::Vector3d p = Eigen::Vector3d::Zero();
    p.head(m.size()) = m;
    scene.true_landmarks.push_back(p);
  }
  for (const auto& x : r.particles) scene.particles.push_back(position_3d(x));
  return scene;
}

/// All files of one back-end on one data set, into `dir`.
template <class Dataset>
void write_run_outputs(const std::filesystem::path& dir, BackendKind kind, const BackendRun<Dataset>& r,
                       const Dataset& data, const RunnerConfig& c) {
  std::filesystem::create_directories(dir);
  const std::string key = backend_key(kind);
  write_steps_csv((dir / (key + "_steps.csv")).string(), r);
  write_map_csv((dir / (key + "_map.csv")).string(), r, data);
  std::vector<io::TumPose> estimated, truth;
  for (std::size_t k = 0; k < r.run.trajectory.size(); ++k) {
    estimated.push_back(tum_pose(static_cast<double>(k + 1), r.run.trajectory[k]));
    if (k + 1 < data.true_poses.size()) truth.push_back(tum_pose(static_cast<double>(k + 1), data.true_poses[k + 1]));
  }
  io::write_tum((dir / (key + "_trajectory.tum")).string(), estimated);
  io::write_tum((dir / "ground_truth.tum").string(), truth);
  mrpt_io::write_scene((dir / (key + ".3Dscene")).string(), scene_content(r, data), {.quantile = c.scene_quantile});
}

/// A JSON number, or null when not finite (JSON has no NaN or Inf).
}  // namespace sextant::runner
