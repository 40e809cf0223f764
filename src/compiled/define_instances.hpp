#pragma once
/// \file Explicit instantiation definitions of every back-end for one model pair: the other half of
/// include/sextant/compiled/extern_instances.hpp, used by the translation units of sextant::compiled.
#include "sextant/backends/ekf_slam.hpp"
#include "sextant/backends/fast_slam.hpp"
#include "sextant/backends/graph_slam.hpp"
#include "sextant/backends/seif_slam.hpp"

/// Instantiates EKF-, SEIF-, Graph- and FastSLAM for the model pair Motion, Sensor (the arguments).
#define SEXTANT_DEFINE_INSTANCES(...)              \
  template class sextant::EkfSlam<__VA_ARGS__>;   \
  template class sextant::SeifSlam<__VA_ARGS__>;  \
  template class sextant::GraphSlam<__VA_ARGS__>; \
  template class sextant::FastSlam<__VA_ARGS__>;
