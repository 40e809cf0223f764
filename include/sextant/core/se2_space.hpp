#pragma once
/// \file Planar poses (x, y, heading) with the heading wrapped: plus and minus add and subtract
/// component-wise and wrap the angle to (-pi, pi].

#include <Eigen/Core>

#include "sextant/core/state_space.hpp"

namespace sextant {

struct Se2Space {
  static constexpr int kDim = 3;
  using Point = Eigen::Vector3d;
  using Tangent = Eigen::Vector3d;

  static Point plus(const Point& x, const Tangent& delta) {
    Point out = x + delta;
    out(2) = wrap_angle(out(2));
    return out;
  }
  static Tangent minus(const Point& a, const Point& b) {
    Tangent out = a - b;
    out(2) = wrap_angle(out(2));
    return out;
  }
  static bool is_finite(const Point& x) { return x.allFinite(); }
};

}  // namespace sextant
