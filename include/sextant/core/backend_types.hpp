#pragma once
/// \file The member types every back-end facade declares from its models (EkfSlam, SeifSlam,
/// GraphSlam, FastSlam): one list, so that the four cannot drift apart.

#include <vector>

#include "sextant/core/concepts.hpp"
#include "sextant/core/gaussian.hpp"
#include "sextant/core/observation.hpp"
#include "sextant/core/state_space.hpp"

/// Inside a back-end class template with parameters named Motion and Sensor: State, Control, Space,
/// Landmark, Measurement, ObservationType, the dimensions X (pose), M (landmark), Z (measurement),
/// PoseEstimate and MapEstimate.
#define SEXTANT_BACKEND_TYPES                                     \
  using State = typename Motion::State;                           \
  using Control = typename Motion::Control;                       \
  using Space = typename Motion::Space;                           \
  using Landmark = typename Sensor::Landmark;                     \
  using Measurement = typename Sensor::Measurement;               \
  using ObservationType = ::sextant::Observation<Measurement>;    \
  static constexpr int X = Motion::kDim;                          \
  static constexpr int M = ::sextant::landmark_dim_v<Sensor>;     \
  static constexpr int Z = ::sextant::measurement_dim_v<Sensor>;  \
  using PoseEstimate = ::sextant::Gaussian<State, X>;             \
  using MapEstimate = std::vector<::sextant::LandmarkEstimate<M>>
