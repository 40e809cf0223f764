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
};

/// One time step of a data stream: the control applied over dt, then what was observed.
template <class Control, class Measurement>
struct Step {
  Control control;
  double dt;
  std::vector<Observation<Measurement>> observations;
};

}  // namespace sextant
