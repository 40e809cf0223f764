#pragma once
/// \file Wall-clock seconds since a steady_clock time point: the stage timers' one measure.

#include <chrono>

namespace sextant {

inline double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace sextant
