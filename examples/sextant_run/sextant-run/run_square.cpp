// sextant-run's square family, docs/runner.md's worked example of adding a data set: a robot with
// wheel odometry drives two laps of a 20 m square among 40 point landmarks and measures range and
// bearing to those within 8 m in front of it. "--dataset square" (seed 1) or "square:<seed>".
// The whole family is this file and its line in dataset_registry.cpp.
#include <cmath>
#include <numbers>
#include <random>
#include <sextant/io/parse_number.hpp>
#include <sextant/sim/ordered_draws.hpp>

#include "dataset_registry.hpp"
#include "landmark_dataset_runs.hpp"

namespace sextant::runner {
namespace {

using SquareDataset = io::LandmarkDataset<Se2Odometry, RangeBearing2D>;

constexpr double kSide = 20.0, kStride = 0.5, kRange = 8.0;
const Eigen::Vector3d kOdometrySigma(0.05, 0.05, 0.01);  ///< per step: m, m, rad
const Eigen::Vector2d kMeasurementSigma(0.1, 0.02);      ///< range [m], bearing [rad]

/// The true odometry increments: kSide / kStride strides along each side, a quarter turn at each corner.
std::vector<Eigen::Vector3d> square_path(int laps) {
  std::vector<Eigen::Vector3d> increments;
  for (int side = 0; side < 4 * laps; ++side) {
    for (int k = 0; k < static_cast<int>(kSide / kStride); ++k) increments.emplace_back(kStride, 0.0, 0.0);
    increments.emplace_back(0.0, 0.0, std::numbers::pi / 2);
  }
  return increments;
}

/// The landmarks seen from `pose`, with noise.
std::vector<Observation<Eigen::Vector2d>> observe(const SquareDataset& data, const Eigen::Vector3d& pose,
                                                  std::mt19937_64& rng) {
  std::normal_distribution<double> unit(0.0, 1.0);
  std::vector<Observation<Eigen::Vector2d>> seen;
  for (const auto& [id, landmark] : data.true_landmarks) {
    const Eigen::Vector2d z = data.sensor.predict(pose, landmark).z;
    if (z(0) > kRange || std::abs(z(1)) > std::numbers::pi / 2) continue;
    const Eigen::Vector2d noise = kMeasurementSigma.cwiseProduct(sim::ordered_draws<2>(unit, rng));
    seen.push_back({id, Eigen::Vector2d(z(0) + noise(0), wrap_angle(z(1) + noise(1)))});
  }
  return seen;
}

SquareDataset simulate_square(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> place(-6.0, kSide + 6.0);
  std::normal_distribution<double> unit(0.0, 1.0);
  SquareDataset data;
  data.path = "square:" + std::to_string(seed);
  data.sensor.Q = kMeasurementSigma.cwiseAbs2().asDiagonal();
  data.prior = {Eigen::Vector3d::Zero(), 1e-6 * Eigen::Matrix3d::Identity()};
  for (LandmarkId id = 0; id < 40; ++id) data.true_landmarks[id] = sim::ordered_draws<2>(place, rng);
  data.true_poses = {data.prior.mean};
  const Eigen::Matrix3d odometry_cov = kOdometrySigma.cwiseAbs2().asDiagonal();
  for (const Eigen::Vector3d& delta : square_path(2)) {
    const auto next = data.motion.predict(data.true_poses.back(), {delta, odometry_cov}, 1.0).x;
    const Eigen::Vector3d measured = delta + kOdometrySigma.cwiseProduct(sim::ordered_draws<3>(unit, rng));
    data.steps.push_back({{measured, odometry_cov}, 1.0, observe(data, next, rng)});
    data.true_poses.push_back(next);
  }
  return data;
}

/// "square" is seed 1; "square:<seed>" any whole number.
std::uint64_t seed_of(const std::string& dataset) {
  if (dataset == "square") return 1;
  const auto number = io::parse_finite_number(dataset.substr(std::string("square:").size()));
  const auto seed = number ? io::as_identifier(*number) : std::nullopt;
  if (!seed) throw invalid_input_error("--dataset " + dataset + ": the seed must be a whole number >= 0 (square:<seed>)");
  return *seed;
}

std::vector<TableRow> run_square(const CliOptions& cli, const std::string& dataset, const std::vector<BackendKind>& kinds,
                                 const RunnerConfig& config) {
  return run_landmark_dataset(cli.output, dataset, simulate_square(seed_of(dataset)), kinds, config);
}

const RegisterDatasetRun registration{"square", run_square};

}  // namespace
}  // namespace sextant::runner
