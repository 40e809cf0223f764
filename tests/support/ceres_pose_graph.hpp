#pragma once
// Ceres as a pose-graph user runs it: the formulation of Ceres's own pose_graph_2d and pose_graph_3d
// examples (written here from Ceres's documentation, not copied): 2D poses as x, y and a yaw on an
// angle manifold, residual (R_a^T (p_b - p_a) - p_ab, wrap(yaw_b - yaw_a - yaw_ab)); 3D poses as a
// position and an Eigen quaternion on EigenQuaternionManifold, residual
// (q_a^-1 (p_b - p_a) - p_ab, 2 vec(q_ab q_ab_est^-1)); both whitened by the square root of the
// edge's information; the first pose held constant; the examples' solver options (their iteration
// limit, SPARSE_NORMAL_CHOLESKY), Ceres's defaults otherwise. Never used by the library.
#include <ceres/autodiff_manifold.h>
#include <ceres/ceres.h>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <vector>

#include "sextant/backends/pose_graph.hpp"
#include "support/ceres_problems.hpp"  // wrap: the angle wrap of the other Ceres peers

namespace sextant::test {

struct AngleManifoldFunctor {
  template <class T>
  bool Plus(const T* x, const T* delta, T* out) const {
    *out = wrap(*x + *delta);
    return true;
  }
  template <class T>
  bool Minus(const T* y, const T* x, T* out) const {
    *out = wrap(*y - *x);
    return true;
  }
};

struct CeresPlanarEdge {
  template <class T>
  bool operator()(const T* xa, const T* ya, const T* yaw_a, const T* xb, const T* yb, const T* yaw_b, T* r) const {
    const T c = ceres::cos(*yaw_a), s = ceres::sin(*yaw_a);
    const T dx = *xb - *xa, dy = *yb - *ya;
    Eigen::Matrix<T, 3, 1> e(c * dx + s * dy - T(z(0)), -s * dx + c * dy - T(z(1)), wrap(*yaw_b - *yaw_a - T(z(2))));
    Eigen::Map<Eigen::Matrix<T, 3, 1>> residual(r);
    residual = sqrt_information.cast<T>() * e;
    return true;
  }
  Eigen::Vector3d z;
  Eigen::Matrix3d sqrt_information;
};

struct CeresSpatialEdge {
  template <class T>
  bool operator()(const T* pa, const T* qa_, const T* pb, const T* qb_, T* r) const {
    Eigen::Map<const Eigen::Matrix<T, 3, 1>> p_a(pa), p_b(pb);
    Eigen::Map<const Eigen::Quaternion<T>> q_a(qa_), q_b(qb_);
    const Eigen::Quaternion<T> q_a_inverse = q_a.conjugate();
    const Eigen::Quaternion<T> q_ab_estimated = q_a_inverse * q_b;
    const Eigen::Matrix<T, 3, 1> p_ab_estimated = q_a_inverse * (p_b - p_a);
    const Eigen::Quaternion<T> delta_q = q_ab.template cast<T>() * q_ab_estimated.conjugate();
    Eigen::Matrix<T, 6, 1> e;
    e << p_ab_estimated - p_ab.template cast<T>(), T(2.0) * delta_q.vec();
    Eigen::Map<Eigen::Matrix<T, 6, 1>> residual(r);
    residual = sqrt_information.cast<T>() * e;
    return true;
  }
  Eigen::Vector3d p_ab;
  Eigen::Quaterniond q_ab;
  Eigen::Matrix<double, 6, 6> sqrt_information;
};

/// Upper-triangular U with U^T U = information.
template <int N>
Eigen::Matrix<double, N, N> square_root_information(const Eigen::Matrix<double, N, N>& information) {
  return information.llt().matrixU();
}

struct CeresPoseGraphResult {
  ceres::Solver::Summary summary;
  double seconds = 0.0;
};

/// The examples' solver options (their iteration limit, SPARSE_NORMAL_CHOLESKY), Ceres's defaults
/// otherwise.
inline CeresPoseGraphResult solve_as_the_examples_do(ceres::Problem& problem, int max_iterations) {
  ceres::Solver::Options options;
  options.max_num_iterations = max_iterations;
  options.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  CeresPoseGraphResult result;
  ceres::Solve(options, &problem, &result.summary);
  result.seconds = result.summary.total_time_in_seconds;
  return result;
}

/// Solves the graph's between edges with Ceres from the graph's current poses and writes the result
/// back into it (poses only; the graph must have no points or priors).
inline CeresPoseGraphResult solve_with_ceres(PoseGraph<PlanarPoses>& graph) {
  const std::size_t n = graph.num_poses();
  std::vector<double> x(n), y(n), yaw(n);
  for (std::size_t k = 0; k < n; ++k) {
    x[k] = graph.poses()[k](0);
    y[k] = graph.poses()[k](1);
    yaw[k] = graph.poses()[k](2);
  }
  ceres::Problem problem;
  auto* angle_manifold = new ceres::AutoDiffManifold<AngleManifoldFunctor, 1, 1>;
  for (const auto& edge : graph.betweens()) {
    auto* cost = new ceres::AutoDiffCostFunction<CeresPlanarEdge, 3, 1, 1, 1, 1, 1, 1>(
        new CeresPlanarEdge{edge.z, square_root_information<3>(edge.information)});
    problem.AddResidualBlock(cost, nullptr, &x[edge.from], &y[edge.from], &yaw[edge.from], &x[edge.to], &y[edge.to],
                             &yaw[edge.to]);
    problem.SetManifold(&yaw[edge.from], angle_manifold);
    problem.SetManifold(&yaw[edge.to], angle_manifold);
  }
  problem.SetParameterBlockConstant(&x[0]);
  problem.SetParameterBlockConstant(&y[0]);
  problem.SetParameterBlockConstant(&yaw[0]);
  const auto result = solve_as_the_examples_do(problem, 100);
  for (std::size_t k = 0; k < n; ++k)
    graph.set_pose(graph.pose_id(k), Eigen::Vector3d(x[k], y[k], wrap(yaw[k])));
  return result;
}

inline CeresPoseGraphResult solve_with_ceres(PoseGraph<SpatialPoses>& graph) {
  const std::size_t n = graph.num_poses();
  std::vector<Eigen::Vector3d> p(n);
  std::vector<Eigen::Quaterniond> q(n);
  for (std::size_t k = 0; k < n; ++k) {
    p[k] = se3::translation(graph.poses()[k]);
    q[k] = Eigen::Quaterniond(se3::rotation(graph.poses()[k]));
  }
  ceres::Problem problem;
  auto* quaternion_manifold = new ceres::EigenQuaternionManifold;
  for (const auto& edge : graph.betweens()) {
    auto* cost = new ceres::AutoDiffCostFunction<CeresSpatialEdge, 6, 3, 4, 3, 4>(new CeresSpatialEdge{
        se3::translation(edge.z), Eigen::Quaterniond(se3::rotation(edge.z)), square_root_information<6>(edge.information)});
    problem.AddResidualBlock(cost, nullptr, p[edge.from].data(), q[edge.from].coeffs().data(), p[edge.to].data(),
                             q[edge.to].coeffs().data());
    problem.SetManifold(q[edge.from].coeffs().data(), quaternion_manifold);
    problem.SetManifold(q[edge.to].coeffs().data(), quaternion_manifold);
  }
  problem.SetParameterBlockConstant(p[0].data());
  problem.SetParameterBlockConstant(q[0].coeffs().data());
  const auto result = solve_as_the_examples_do(problem, 200);
  for (std::size_t k = 0; k < n; ++k)
    graph.set_pose(graph.pose_id(k), se3::make(q[k].normalized().toRotationMatrix(), p[k]));
  return result;
}

}  // namespace sextant::test
