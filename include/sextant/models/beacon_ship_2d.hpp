#pragma once
/// \file The thesis's 2D beacon-ship models (seed 000, §4.2.1, eqs. 94-99): a ship with a log
/// (speed) and a compass (heading) that measures beacons as offsets m - x.

#include <Eigen/Core>
#include <cmath>

#include "sextant/core/model_results.hpp"
#include "sextant/core/state_space.hpp"

namespace sextant {

/// How the control-space noise (sigma_v, sigma_heading) enters the state.
enum class HeadingNoise {
  /// The thesis: mean g(u) and R = V M V^T with V = dg/du (eqs. 11, 96). With a compass heading
  /// phi_m = phi + e, E[cos phi_m] = cos(phi) exp(-sigma^2 / 2): this mean falls short of the true
  /// displacement by 3.4% at 15 degrees, a bias that accumulates on legs without beacons.
  linearized,
  /// Unbiased: the mean is scaled by exp(sigma^2 / 2), which makes it an unbiased estimate of the
  /// true displacement, and R is the covariance of its error for Gaussian speed and heading noise,
  /// averaged over the true heading the filter knows only to sigma (derivation in
  /// docs/derivations/ship_heading_noise.md).
  unbiased,
};

/// Motion model of the ship, state x = (x, y) (eq. 94), control u = (v, heading) (eq. 95):
/// x' = x + dt v (cos heading, sin heading) (eq. 96), G = I (eq. 97).
struct BeaconShip2D {
  using State = Eigen::Vector2d;
  using Control = Eigen::Vector2d;
  using Space = EuclideanSpace<2>;
  static constexpr int kDim = 2;

  double sigma_v = 1.0;              ///< std of the log's speed, state units per time unit
  double sigma_heading = 0.2617994;  ///< std of the compass heading, rad (15 degrees)
  HeadingNoise heading_noise = HeadingNoise::unbiased;

  MotionPrediction<State, kDim> predict(const State& x, const Control& u, double dt) const {
    const double v = u(0), c = std::cos(u(1)), s = std::sin(u(1));
    MotionPrediction<State, kDim> out;
    out.J_x_x.setIdentity();
    if (heading_noise == HeadingNoise::linearized) {
      out.x = x + dt * v * Eigen::Vector2d(c, s);
      Eigen::Matrix2d V;  // dx'/du
      V << dt * c, -dt * v * s, dt * s, dt * v * c;
      const Eigen::Vector2d m(sigma_v * sigma_v, sigma_heading * sigma_heading);
      out.R = V * m.asDiagonal() * V.transpose();
      out.R = 0.5 * (out.R + out.R.transpose()).eval();
    } else {
      const double var_h = sigma_heading * sigma_heading;
      const double speed_second_moment = v * v + sigma_v * sigma_v;
      out.x = x + dt * v * std::exp(0.5 * var_h) * Eigen::Vector2d(c, s);
      // Error covariance dt^2/2 [a I + b Rot(2 heading)], Rot(t) = [cos t, sin t; sin t, -cos t].
      const double a = speed_second_moment * std::exp(var_h) - v * v;
      // The filter knows the heading only to sigma: averaged over it, E[Rot(2h)] = exp(-2 var_h) Rot(2 h_m).
      const double b = std::exp(-2.0 * var_h) * (speed_second_moment * std::exp(-var_h) - v * v);
      const double c2 = c * c - s * s, s2 = 2.0 * s * c;
      Eigen::Matrix2d rot;
      rot << c2, s2, s2, -c2;
      out.R = 0.5 * dt * dt * (a * Eigen::Matrix2d::Identity() + b * rot);
    }
    return out;
  }
};

/// Measurement model of a beacon seen as an offset from the ship (eq. 98): z = m - x, with
/// H = [-I  I] (eq. 99) and isotropic noise Q = sigma^2 I; inverse model m = x + z.
struct BeaconOffset2D {
  using Landmark = Eigen::Vector2d;
  using Measurement = Eigen::Vector2d;

  double sigma = 2.0;  ///< std of each offset component, state units

  MeasurementPrediction<2, 2, 2> predict(const Eigen::Vector2d& x, const Landmark& m) const {
    return {m - x, -Eigen::Matrix2d::Identity(), Eigen::Matrix2d::Identity(), noise()};
  }

  Eigen::Vector2d residual(const Measurement& z, const Measurement& z_hat) const { return z - z_hat; }

  LandmarkInit<2, 2, 2> initialize(const Eigen::Vector2d& x, const Measurement& z) const {
    return {x + z, Eigen::Matrix2d::Identity(), Eigen::Matrix2d::Identity(), noise()};
  }

  Eigen::Matrix2d noise() const { return sigma * sigma * Eigen::Matrix2d::Identity(); }
};

}  // namespace sextant

// Compiled mode (docs/build_times.md): the shipped back-end x model pairs this header completes
// are declared extern when the program links sextant::compiled.
#define SEXTANT_DECLARED_BEACON_SHIP_2D
#include "sextant/compiled/extern_instances.hpp"
