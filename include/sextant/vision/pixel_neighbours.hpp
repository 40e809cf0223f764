#pragma once
/// \file The points of one image near each other: for a point's pixel, the others within a radius,
/// found through the pixels sorted by column (detail::SortedIndex) instead of a scan of all. The
/// neighbourhood that the slant of a surface (slant_noise.hpp) and the support of a disparity
/// (disparity_support.hpp) are judged over.

#include <Eigen/Core>
#include <cstddef>
#include <span>
#include <vector>

#include "sextant/vision/stereo_matching.hpp"

namespace sextant::vision::detail {

/// Holds a view of the pixels: they must outlive it.
class PixelNeighbours {
 public:
  explicit PixelNeighbours(std::span<const Eigen::Vector2d> pixels) : pixels_(pixels), by_u_(columns(pixels)) {}

  /// The indices of the pixels within `radius` of pixel i, i itself included, into `out` (cleared first).
  void within(std::size_t i, double radius, std::vector<int>& out) const {
    out.clear();
    const double r2 = radius * radius;
    for (const int k : by_u_.band(pixels_[i].x(), radius))
      if ((pixels_[static_cast<std::size_t>(k)] - pixels_[i]).squaredNorm() <= r2) out.push_back(k);
  }

 private:
  static std::vector<double> columns(std::span<const Eigen::Vector2d> pixels) {
    std::vector<double> us;
    us.reserve(pixels.size());
    for (const auto& p : pixels) us.push_back(p.x());
    return us;
  }

  std::span<const Eigen::Vector2d> pixels_;
  SortedIndex by_u_;
};

}  // namespace sextant::vision::detail
