#pragma once
/// \file A planar robot driven by a forward velocity v and a turn rate w held for dt (a unicycle,
/// differential drive: MRCLAM's odometry, Thrun's velocity motion model, Probabilistic Robotics
/// §5.3). The motion over dt is an arc; it is computed as an odometry increment in the robot frame
/// and composed by Se2Odometry, so predict() and the GraphSLAM factor between() are Se2Odometry's.

#include <Eigen/Core>
#include <array>
#include <cmath>

#include "sextant/models/se2_odometry.hpp"

namespace sextant {

/// Forward velocity [m/s] and turn rate [rad/s], constant over the step.
struct UnicycleControl {
  double v = 0.0;
  double w = 0.0;
  bool allFinite() const { return std::isfinite(v) && std::isfinite(w); }
};

/// Thrun's velocity motion model. Over dt the robot moves along an arc of length L = v dt sinc(phi)
/// (chord) at angle phi = w dt / 2 from its heading and turns by w dt (Thrun Table 5.3, written
/// with sinc so that w -> 0 is the straight line, not a division by zero):
///   delta = (L cos phi, L sin phi, w dt)  in the robot frame.
/// Noise (Thrun eq. 5.10): the executed velocities are v + e_v, w + e_w with
///   var e_v = a1 v^2 + a2 w^2,  var e_w = a3 v^2 + a4 w^2,
/// and a final rotation g dt with var g = a5 v^2 + a6 w^2; the increment's covariance is
/// V M V^T + diag(0, 0, var g dt^2) with V = d delta / d(v, w), plus `floor_rate` dt, a small
/// variance per second on (x, y, heading) in the robot frame that keeps R invertible when the
/// robot stands still (GraphSLAM's motion factor needs R^-1).
struct Unicycle {
  using State = Eigen::Vector3d;
  using Control = UnicycleControl;
  using Space = Se2Space;
  static constexpr int kDim = 3;

  std::array<double, 6> alpha{0.1, 0.01, 0.01, 0.1, 0.0, 0.01};
  Eigen::Vector3d floor_rate = Eigen::Vector3d(1e-6, 1e-6, 1e-6);

  /// The arc as an increment in the robot frame with its covariance.
  OdometryIncrement2D increment(const Control& u, double dt) const {
    const double phi = 0.5 * u.w * dt;
    const double s = sinc(phi), ds = sinc_derivative(phi);
    const double length = u.v * dt * s, c = std::cos(phi), sn = std::sin(phi);
    OdometryIncrement2D out;
    out.delta << length * c, length * sn, u.w * dt;
    // d delta / dv and d delta / dw (dphi/dw = dt/2).
    Eigen::Matrix<double, 3, 2> V;
    const double dlength_dw = u.v * dt * ds * 0.5 * dt;
    V.col(0) << dt * s * c, dt * s * sn, 0.0;
    V.col(1) << dlength_dw * c - length * sn * 0.5 * dt, dlength_dw * sn + length * c * 0.5 * dt, dt;
    const double v2 = u.v * u.v, w2 = u.w * u.w;
    const Eigen::Vector2d M(alpha[0] * v2 + alpha[1] * w2, alpha[2] * v2 + alpha[3] * w2);
    out.cov = V * M.asDiagonal() * V.transpose();
    out.cov(2, 2) += (alpha[4] * v2 + alpha[5] * w2) * dt * dt;
    out.cov.diagonal() += floor_rate * dt;
    return out;
  }

  MotionPrediction<State, 3> predict(const State& x, const Control& u, double dt) const {
    return Se2Odometry{}.predict(x, increment(u, dt), dt);
  }

  BetweenFactor<3> between(const State& from, const State& to, const Control& u, double dt) const {
    return Se2Odometry{}.between(from, to, increment(u, dt), dt);
  }

 private:
  /// sin(a)/a and its derivative (a cos a - sin a)/a^2, by their series near 0.
  static double sinc(double a) { return std::abs(a) < 1e-4 ? 1.0 - a * a / 6.0 : std::sin(a) / a; }
  static double sinc_derivative(double a) {
    return std::abs(a) < 1e-4 ? -a / 3.0 + a * a * a / 30.0 : (a * std::cos(a) - std::sin(a)) / (a * a);
  }
};

}  // namespace sextant

// Compiled mode (docs/build_times.md): the shipped back-end x model pairs this header completes
// are declared extern when the program links sextant::compiled.
#define SEXTANT_DECLARED_UNICYCLE
#include "sextant/compiled/extern_instances.hpp"
