#pragma once
/// \file Deterministic, seeded simulator of the thesis's 2D beacon-ship experiment (seed 000,
/// §4.2.1): a ship sails counter-clockwise around a rectangular island with beacons along its
/// coast, measuring speed and heading (noisy controls) and beacon offsets within sensor range.
/// The route has one long leg far from any beacon (no corrections, the error grows, as between
/// steps 600 and 900 in the thesis's Figure 17) and closes the loop near the end.

#include <Eigen/Core>
#include <cmath>
#include <map>
#include <numbers>
#include <random>
#include <vector>

#include "sextant/core/gaussian.hpp"
#include "sextant/core/observation.hpp"
#include "sextant/models/beacon_ship_2d.hpp"
#include "sextant/sim/ordered_draws.hpp"

namespace sextant::sim {

/// Parameters of the ship simulation; units are km and hours.
struct Ship2DOptions {
  std::uint64_t seed = 1;
  int num_steps = 1390;                  ///< thesis: 1390 time instances
  double dt = 1.0;                       ///< h
  double speed = 10.0;                   ///< km/h, mean true speed
  double speed_variation = 1.0;          ///< km/h, slow sinusoidal variation of the true speed
  double heading_weave = 0.1;            ///< rad, amplitude of the true heading's weave about the route
  double sigma_v = 1.0;                  ///< km/h, std of the log (speed measurement)
  double sigma_heading = 15.0 * std::numbers::pi / 180.0;  ///< rad, std of the compass (thesis: 15 deg)
  double sigma_beacon = 2.0;             ///< km, std of each component of a beacon offset measurement
  double sensor_range = 150.0;           ///< km
  double island_width = 4000.0;          ///< km, east-west extent of the route
  double island_height = 2000.0;         ///< km, north-south extent of the route
  double coast_offset = 60.0;            ///< km, distance from the route to the coast (beacon line)
  double beacon_spacing = 100.0;         ///< km, along the coast
  double beacon_jitter = 20.0;           ///< km, random displacement of each beacon
  double open_sea_from_x = 1000.0;       ///< km: no beacons on the north coast east of this (the open-sea leg)
  double prior_sigma = 0.5;              ///< km, std of the initial pose estimate
  HeadingNoise heading_noise = HeadingNoise::unbiased;  ///< noise model handed to the filter
};

/// A simulated run: the step stream a back-end consumes, the models with the simulator's noise,
/// the prior, and the ground truth.
struct Ship2DDataset {
  BeaconShip2D motion;
  BeaconOffset2D sensor;
  Gaussian<Eigen::Vector2d, 2> prior;
  std::vector<Step<Eigen::Vector2d, Eigen::Vector2d>> steps;
  std::vector<Eigen::Vector2d> true_poses;              ///< true_poses[k]: after step k; [0] is the start
  std::map<LandmarkId, Eigen::Vector2d> true_landmarks;
};

namespace detail {

inline std::vector<Eigen::Vector2d> route_corners(const Ship2DOptions& o) {
  return {{0.0, 0.0}, {o.island_width, 0.0}, {o.island_width, o.island_height}, {0.0, o.island_height}};
}

/// Beacons every beacon_spacing along the coast (the route inset by coast_offset), except on the
/// open-sea stretch of the north coast.
inline std::map<LandmarkId, Eigen::Vector2d> place_beacons(const Ship2DOptions& o, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> jitter(-o.beacon_jitter, o.beacon_jitter);
  const double d = o.coast_offset;
  const std::vector<Eigen::Vector2d> coast = {
      {d, d}, {o.island_width - d, d}, {o.island_width - d, o.island_height - d}, {d, o.island_height - d}};
  std::map<LandmarkId, Eigen::Vector2d> beacons;
  LandmarkId next_id = 0;
  for (std::size_t edge = 0; edge < coast.size(); ++edge) {
    const Eigen::Vector2d a = coast[edge], b = coast[(edge + 1) % coast.size()];
    const int count = static_cast<int>(std::floor((b - a).norm() / o.beacon_spacing));
    for (int i = 0; i < count; ++i) {
      const Eigen::Vector2d p = a + (b - a) * (i + 0.5) / count + ordered_draws<2>(jitter, rng);
      const bool open_sea = edge == 2 && p.x() > o.open_sea_from_x;
      if (!open_sea) beacons.emplace(next_id++, p);
    }
  }
  return beacons;
}

}  // namespace detail

/// Simulates one run. The same options (including seed) always give the same data.
inline Ship2DDataset simulate_ship_2d(const Ship2DOptions& o) {
  std::mt19937_64 rng(o.seed);
  std::normal_distribution<double> unit(0.0, 1.0);
  Ship2DDataset data;
  data.motion = BeaconShip2D{o.sigma_v, o.sigma_heading, o.heading_noise};
  data.sensor = BeaconOffset2D{o.sigma_beacon};
  data.true_landmarks = detail::place_beacons(o, rng);

  const auto corners = detail::route_corners(o);
  Eigen::Vector2d pose = corners[0];
  data.true_poses.push_back(pose);
  data.prior.mean = pose + o.prior_sigma * ordered_draws<2>(unit, rng);
  data.prior.cov = o.prior_sigma * o.prior_sigma * Eigen::Matrix2d::Identity();

  std::size_t target = 1;
  for (int k = 0; k < o.num_steps; ++k) {
    const double phase = 2.0 * std::numbers::pi * k;
    const double v = o.speed + o.speed_variation * std::sin(phase / 97.0);
    if ((corners[target] - pose).norm() < v * o.dt) target = (target + 1) % corners.size();
    const Eigen::Vector2d to_target = corners[target] - pose;
    const double heading = std::atan2(to_target.y(), to_target.x()) + o.heading_weave * std::sin(phase / 37.0);
    pose += o.dt * v * Eigen::Vector2d(std::cos(heading), std::sin(heading));
    data.true_poses.push_back(pose);

    Step<Eigen::Vector2d, Eigen::Vector2d> step;
    step.dt = o.dt;
    const Eigen::Vector2d control_noise = ordered_draws<2>(unit, rng);
    step.control = Eigen::Vector2d(v + o.sigma_v * control_noise.x(), heading + o.sigma_heading * control_noise.y());
    for (const auto& [id, beacon] : data.true_landmarks)
      if ((beacon - pose).norm() <= o.sensor_range)
        step.observations.push_back({id, beacon - pose + o.sigma_beacon * ordered_draws<2>(unit, rng)});
    data.steps.push_back(std::move(step));
  }
  return data;
}

}  // namespace sextant::sim
