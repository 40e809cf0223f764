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
};

}  // namespace sextant
