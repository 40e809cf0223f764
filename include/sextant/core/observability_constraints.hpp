#pragma once
/// \file Observability constraints (OC-EKF: Huang, Mourikis and Roumeliotis, "Observability-based
/// rules for designing consistent EKF SLAM estimators", IJRR 2010; Hesch et al., IEEE T-RO 2014).
/// SLAM cannot observe where the whole world is: moving the robot and every landmark by one rigid
/// motion leaves every measurement the same. A linearized filter whose Jacobians are taken at
/// different estimates loses that invariance and gains information along those directions, which
/// makes it overconfident (the globe's rotation NEES, docs/results/globe.md). The constraints give
/// back the invariance: with N(x) the directions of the world's rigid motions at state x,
/// - the transition G of the robot is replaced by the G* nearest to it (Frobenius) with
///   G* N(x_prev) = N(x_next), x_prev and x_next the robot states after the last and this
///   prediction;
/// - an observation's H = [H_x, H_m] by the H* nearest to it with H* [N_x; N_m] = 0, N_x at the
///   last prediction and N_m at the landmark's first estimate (landmarks do not move, so their rows
///   of N must not change).
/// Then N(x_k) spans a null space of the filter's observability matrix at every step, as for the
/// true system. A state space offers its robot rows of N as `Space::world_motion_directions(x)`.
/// Derivation: docs/derivations/observability_constraints.md.

#include <Eigen/Core>
#include <Eigen/LU>
#include <type_traits>

#include "sextant/core/error.hpp"
#include "sextant/core/linearized_observation.hpp"
#include "sextant/core/so3.hpp"

namespace sextant {

/// Whether the state space names the directions of the world's rigid motions at a state.
template <class Space, class Point = typename Space::Point>
inline constexpr bool has_world_motion_directions_v =
    requires(const Point& x) { Space::world_motion_directions(x); };

/// The rows of a point landmark in N: a translation t and a small rotation w of the world move it
/// by t + w x l. 3D: [I, -[l]x] (translation, then rotation about the world's axes).
inline Eigen::Matrix<double, 3, 6> point_world_motion_directions(const Eigen::Vector3d& l) {
  Eigen::Matrix<double, 3, 6> N;
  N << Eigen::Matrix3d::Identity(), -so3::hat(l);
  return N;
}

/// 2D: [I, (-l_y, l_x)] (translation, then rotation about the vertical).
inline Eigen::Matrix<double, 2, 3> point_world_motion_directions(const Eigen::Vector2d& l) {
  Eigen::Matrix<double, 2, 3> N;
  N << 1, 0, -l.y(), 0, 1, l.x();
  return N;
}

/// G* = G - (G N_prev - N_next) (N_prev^T N_prev)^-1 N_prev^T: the transition nearest to G that maps
/// the world's motions at the last prediction onto those at this one.
template <int X, int U>
Eigen::Matrix<double, X, X> constrained_transition(const Eigen::Matrix<double, X, X>& G,
                                                   const Eigen::Matrix<double, X, U>& N_prev,
                                                   const Eigen::Matrix<double, X, U>& N_next) {
  const Eigen::Matrix<double, U, U> gram = N_prev.transpose() * N_prev;
  const Eigen::FullPivLU<Eigen::Matrix<double, U, U>> lu(gram);
  if (!lu.isInvertible()) throw numerical_error("observability constraints: the world's motions are degenerate here");
  return G - (G * N_prev - N_next) * lu.solve(N_prev.transpose());
}

/// Replaces lin's H by the H* nearest to it with H* [N_x; N_m] = 0 (H N projected out).
template <int Z, int X, int M, int U>
void constrain_observation(LinearizedObservation<Z, X, M>& lin, const Eigen::Matrix<double, X, U>& N_x,
                           const Eigen::Matrix<double, M, U>& N_m) {
  const Eigen::Matrix<double, U, U> gram = N_x.transpose() * N_x + N_m.transpose() * N_m;
  const Eigen::FullPivLU<Eigen::Matrix<double, U, U>> lu(gram);
  if (!lu.isInvertible()) throw numerical_error("observability constraints: the world's motions are degenerate here");
  const Eigen::Matrix<double, Z, U> HN = lin.J_z_x * N_x + lin.J_z_m * N_m;
  const Eigen::Matrix<double, Z, U> A = lu.solve(HN.transpose()).transpose();  // H N (N^T N)^-1
  lin.J_z_x -= A * N_x.transpose();
  lin.J_z_m -= A * N_m.transpose();
}

/// Whether a robot state space and landmark type can keep the constraints: the space names the
/// world's motions and the landmark is a point.
template <class Space, class Landmark>
inline constexpr bool observability_constrainable_v =
    has_world_motion_directions_v<Space> && requires(const Landmark& l) { point_world_motion_directions(l); };

/// The filters' step (EKF, SEIF): the robot's transition G, constrained when `on`, from the last
/// prediction's state `previous` to this one's `next`.
template <class Space, int X>
Eigen::Matrix<double, X, X> robot_transition(bool on, const Eigen::Matrix<double, X, X>& G,
                                             const typename Space::Point& previous, const typename Space::Point& next) {
  if constexpr (has_world_motion_directions_v<Space>)
    if (on) return constrained_transition(G, Space::world_motion_directions(previous), Space::world_motion_directions(next));
  return G;
}

/// The filters' step: an observation's Jacobians constrained when `on`, at the last prediction's
/// robot state and the landmark's first estimate.
template <class Space, class Landmark, int Z, int X, int M>
void constrain_observation_if(bool on, LinearizedObservation<Z, X, M>& lin, const typename Space::Point& propagated,
                              const Landmark& first) {
  if constexpr (observability_constrainable_v<Space, Landmark>)
    if (on) constrain_observation(lin, Space::world_motion_directions(propagated), point_world_motion_directions(first));
}

/// Throws invalid_input_error when the constraints are asked of a model pair that cannot keep them.
template <class Space, class Landmark>
void require_constrainable(bool on) {
  if (on && !observability_constrainable_v<Space, Landmark>)
    throw invalid_input_error("observability_constraints: this state space does not name the world's rigid motions "
                              "(Space::world_motion_directions) or its landmarks are not points");
}

}  // namespace sextant
