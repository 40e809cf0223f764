#pragma once
/// \file The looping world of the SEIF and FastSLAM benchmarks and the soak test: n beacons on a
/// circle one unit apart, a ship sailing a circle 3 units inside, one beacon further per step,
/// seeing the 4 nearest. Noise-free: callers add their own.
#include <malloc.h>

#include <Eigen/Core>
#include <cmath>
#include <numbers>
#include <vector>

#include "sextant/core/observation.hpp"
#include "sextant/models/beacon_ship_2d.hpp"

namespace sextant::testing {

/// Heap bytes in use (glibc): small blocks plus the mmapped large ones (a big covariance lives there).
inline std::size_t heap_in_use() {
  const auto info = mallinfo2();
  return info.uordblks + info.hblkhd;
}

struct CircleWorld {
  static constexpr int kObservationsPerStep = 4;

  explicit CircleWorld(int landmarks) : count(landmarks), radius(landmarks / (2.0 * std::numbers::pi)) {}
  double angle(int j) const { return 2.0 * std::numbers::pi * (j % count) / count; }
  Eigen::Vector2d beacon(int j) const { return radius * Eigen::Vector2d(std::cos(angle(j)), std::sin(angle(j))); }
  Eigen::Vector2d ship(int step) const { return (radius - 3.0) * Eigen::Vector2d(std::cos(angle(step)), std::sin(angle(step))); }
  /// (speed, heading) from ship(step - 1) to ship(step).
  Eigen::Vector2d control(int step) const {
    const Eigen::Vector2d d = ship(step) - ship(step - 1);
    return {d.norm(), std::atan2(d.y(), d.x())};
  }
  std::vector<Observation<Eigen::Vector2d>> observations(int step) const {
    std::vector<Observation<Eigen::Vector2d>> out;
    for (int i = 0; i < kObservationsPerStep; ++i) {
      const int j = (step + i) % count;
      out.push_back({static_cast<LandmarkId>(j), beacon(j) - ship(step)});
    }
    return out;
  }
  /// Every beacon as seen from the start (to map them all in one update).
  std::vector<Observation<Eigen::Vector2d>> all_beacons() const {
    std::vector<Observation<Eigen::Vector2d>> out;
    for (int j = 0; j < count; ++j) out.push_back({static_cast<LandmarkId>(j), beacon(j) - ship(0)});
    return out;
  }

  int count;
  double radius;
};

}  // namespace sextant::testing
