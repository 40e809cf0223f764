#pragma once
// The GraphSLAM problems of sextant written independently for Ceres (autodiff cost functors):
// the peer for tests and benchmarks. Never used by the library.
#include <ceres/ceres.h>

#include <Eigen/Cholesky>
#include <map>
#include <numbers>
#include <vector>

#include "sextant/core/observation.hpp"
#include "sextant/models/point_in_robot_frame_2d.hpp"
#include "sextant/models/se2_odometry.hpp"

namespace sextant::test {

/// Upper factor U with U^T U = cov^-1: residuals are whitened as U r.
template <int N>
Eigen::Matrix<double, N, N> whitening(const Eigen::Matrix<double, N, N>& cov) {
  const Eigen::Matrix<double, N, N> information = cov.llt().solve(Eigen::Matrix<double, N, N>::Identity());
  return information.llt().matrixU();
}

template <class T>
T wrap(const T& angle) {
  const T two_pi = T(2.0 * std::numbers::pi);
  return angle - two_pi * ceres::floor((angle + T(std::numbers::pi)) / two_pi);
}

/// U (x - prior) for an N-dimensional parameter block.
template <int N>
struct PriorCost {
  template <class T>
  bool operator()(const T* x, T* r) const {
    Eigen::Matrix<T, N, 1> e;
    for (int i = 0; i < N; ++i) e(i) = x[i] - T(mean(i));
    if constexpr (N == 3) e(2) = wrap(e(2));
    Eigen::Map<Eigen::Matrix<T, N, 1>> residual(r);
    residual = U.template cast<T>() * e;
    return true;
  }
  Eigen::Matrix<double, N, 1> mean;
  Eigen::Matrix<double, N, N> U;
};

/// Ship: x_to - x_from - displacement (the beacon ship's motion is a translation).
struct ShipMotionCost {
  template <class T>
  bool operator()(const T* from, const T* to, T* r) const {
    Eigen::Matrix<T, 2, 1> e(to[0] - from[0] - T(d(0)), to[1] - from[1] - T(d(1)));
    Eigen::Map<Eigen::Matrix<T, 2, 1>> residual(r);
    residual = U.cast<T>() * e;
    return true;
  }
  Eigen::Vector2d d;
  Eigen::Matrix2d U;
};

/// Ship: m - x - z.
struct ShipBeaconCost {
  template <class T>
  bool operator()(const T* x, const T* m, T* r) const {
    Eigen::Matrix<T, 2, 1> e(m[0] - x[0] - T(z(0)), m[1] - x[1] - T(z(1)));
    Eigen::Map<Eigen::Matrix<T, 2, 1>> residual(r);
    residual = U.cast<T>() * e;
    return true;
  }
  Eigen::Vector2d z;
  Eigen::Matrix2d U;
};

/// SE(2) odometry in the robot frame: Rot(h_i)^T (p_j - p_i) - d_xy, wrap(h_j - h_i - d_h).
struct OdometryCost {
  template <class T>
  bool operator()(const T* a, const T* b, T* r) const {
    const T c = ceres::cos(a[2]), s = ceres::sin(a[2]);
    const T dx = b[0] - a[0], dy = b[1] - a[1];
    Eigen::Matrix<T, 3, 1> e(c * dx + s * dy - T(delta(0)), -s * dx + c * dy - T(delta(1)), wrap(b[2] - a[2] - T(delta(2))));
    Eigen::Map<Eigen::Matrix<T, 3, 1>> residual(r);
    residual = U.cast<T>() * e;
    return true;
  }
  Eigen::Vector3d delta;
  Eigen::Matrix3d U;
};

/// A landmark in the robot frame: Rot(h)^T (m - p) - z.
struct PointCost {
  template <class T>
  bool operator()(const T* x, const T* m, T* r) const {
    const T c = ceres::cos(x[2]), s = ceres::sin(x[2]);
    const T dx = m[0] - x[0], dy = m[1] - x[1];
    Eigen::Matrix<T, 2, 1> e(c * dx + s * dy - T(z(0)), -s * dx + c * dy - T(z(1)));
    Eigen::Map<Eigen::Matrix<T, 2, 1>> residual(r);
    residual = U.cast<T>() * e;
    return true;
  }
  Eigen::Vector2d z;
  Eigen::Matrix2d U;
};

/// How Ceres decides to stop.
enum class CeresStopping {
  defaults,  ///< Ceres's own defaults (as a Ceres user runs it): function, gradient, parameter tolerances
  optimum,   ///< run to the stationary point, for tests that compare optima
};

/// Parameter storage and the problem; poses and landmarks start from the given values.
template <int X>
struct CeresGraph {
  std::vector<Eigen::Matrix<double, X, 1>> poses;
  std::map<LandmarkId, Eigen::Vector2d> landmarks;
  ceres::Problem problem;

  ceres::Solver::Summary solve(ceres::LinearSolverType type, CeresStopping stopping = CeresStopping::optimum,
                               int threads = 1) {
    ceres::Solver::Options options;
    options.linear_solver_type = type;
    options.sparse_linear_algebra_library_type = ceres::SUITE_SPARSE;
    if (stopping == CeresStopping::optimum) {
      // Stop on the parameter change alone, and let LM's damping vanish near the optimum: with the
      // defaults Ceres stops 1.5e-6 short of the stationary point on the 2000-pose cityTrees chain
      // (its damping floor, min_lm_diagonal, stalls the flattest direction; a Gauss-Newton step
      // from there still moves 1.5e-6).
      options.max_num_iterations = 200;
      options.min_lm_diagonal = 1e-32;
      options.initial_trust_region_radius = 1e8;
      options.function_tolerance = 0.0;
      options.gradient_tolerance = 0.0;
      options.parameter_tolerance = 1e-15;
    }
    options.num_threads = threads;
    ceres::Solver::Summary summary;
    ceres::Solve(options, &problem, &summary);
    return summary;
  }
};

/// The beacon-ship problem: prior, motions, beacon offsets; initial values given.
template <class Steps>
void build_ship(CeresGraph<2>& g, const Eigen::Vector2d& prior_mean, const Eigen::Matrix2d& prior_cov, const Steps& steps,
                const std::vector<Eigen::Matrix2d>& motion_cov, const std::vector<Eigen::Vector2d>& displacement,
                const Eigen::Matrix2d& beacon_cov) {
  g.problem.AddResidualBlock(new ceres::AutoDiffCostFunction<PriorCost<2>, 2, 2>(new PriorCost<2>{prior_mean, whitening<2>(prior_cov)}),
                             nullptr, g.poses[0].data());
  const Eigen::Matrix2d U_beacon = whitening<2>(beacon_cov);
  for (std::size_t k = 0; k < steps.size(); ++k) {
    g.problem.AddResidualBlock(new ceres::AutoDiffCostFunction<ShipMotionCost, 2, 2, 2>(
                                   new ShipMotionCost{displacement[k], whitening<2>(motion_cov[k])}),
                               nullptr, g.poses[k].data(), g.poses[k + 1].data());
    for (const auto& obs : steps[k].observations)
      g.problem.AddResidualBlock(new ceres::AutoDiffCostFunction<ShipBeaconCost, 2, 2, 2>(new ShipBeaconCost{obs.z, U_beacon}),
                                 nullptr, g.poses[k + 1].data(), g.landmarks.at(obs.landmark_id).data());
  }
}

/// A planar odometry + landmark problem (iSAM files); the first pose is held by a prior.
template <class Steps>
void build_planar(CeresGraph<3>& g, const Eigen::Matrix3d& prior_cov, const std::vector<Observation<Eigen::Vector2d>>& initial,
                  const Steps& steps, const Eigen::Matrix2d& landmark_cov) {
  const Eigen::Vector3d first = g.poses[0];
  g.problem.AddResidualBlock(new ceres::AutoDiffCostFunction<PriorCost<3>, 3, 3>(new PriorCost<3>{first, whitening<3>(prior_cov)}),
                             nullptr, g.poses[0].data());
  const Eigen::Matrix2d U = whitening<2>(landmark_cov);
  auto add_points = [&](std::size_t pose, const std::vector<Observation<Eigen::Vector2d>>& observations) {
    for (const auto& obs : observations)
      g.problem.AddResidualBlock(new ceres::AutoDiffCostFunction<PointCost, 2, 3, 2>(new PointCost{obs.z, U}), nullptr,
                                 g.poses[pose].data(), g.landmarks.at(obs.landmark_id).data());
  };
  add_points(0, initial);
  for (std::size_t k = 0; k < steps.size(); ++k) {
    g.problem.AddResidualBlock(new ceres::AutoDiffCostFunction<OdometryCost, 3, 3, 3>(
                                   new OdometryCost{steps[k].control.delta, whitening<3>(steps[k].control.cov)}),
                               nullptr, g.poses[k].data(), g.poses[k + 1].data());
    add_points(k + 1, steps[k].observations);
  }
}

}  // namespace sextant::test
