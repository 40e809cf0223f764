#pragma once
/// \file Observations and steps: what a front-end hands to a back-end.

#include <cstdint>
#include <vector>

namespace sextant {

/// Identifier a front-end gives a landmark (known data association).
using LandmarkId = std::uint64_t;

/// One measurement z of the landmark with the given id.
template <class Measurement>
struct Observation {
  LandmarkId landmark_id;
  Measurement z;
  /// The measurement's standard deviations as a multiple of the sensor model's: every back-end
  /// weighs it with noise_scale^2 Q (with_noise_scale). 1 is the model's own noise; a front-end
  /// that knows one measurement is worse than the model says (a feature seen obliquely, one found
  /// at a coarse pyramid level) says so here. Positive and finite (require_valid_observations).
  double noise_scale = 1.0;
};

/// A model's prediction or inverse model (anything with a noise matrix Q) for a measurement whose
/// noise is `noise_scale` times the model's: Q becomes noise_scale^2 Q (exactly Q at 1).
template <class WithNoise>
WithNoise with_noise_scale(WithNoise result, double noise_scale) {
  result.Q *= noise_scale * noise_scale;
  return result;
}

/// One time step of a data stream: the control applied over dt, then what was observed.
template <class Control, class Measurement>
struct Step {
  Control control;
  double dt;
  std::vector<Observation<Measurement>> observations;
};

}  // namespace sextant
