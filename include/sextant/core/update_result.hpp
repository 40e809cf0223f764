#pragma once
/// \file What an update step reports.

#include <cstddef>
#include <vector>

#include "sextant/core/observation.hpp"

namespace sextant {

struct UpdateResult {
  std::size_t corrected = 0;             ///< observations of known landmarks used in the correction
  std::size_t initialized = 0;           ///< new landmarks added to the map
  std::vector<LandmarkId> rejected;      ///< observations rejected by the Mahalanobis gate
  /// Observations the sensor model cannot use at the current estimate (unobservable_error: a point
  /// behind or too near the camera, outside its field of view, a disparity <= 0 or below the
  /// smallest for a new landmark), skipped one by one; a new landmark listed here is not added.
  std::vector<LandmarkId> unusable;
};

}  // namespace sextant
