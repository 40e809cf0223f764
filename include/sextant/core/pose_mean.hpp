#pragma once
/// \file The robot's pose mean from any back-end: pose_mean() where it has one (SEIF, whose pose()
/// also recovers a covariance), else pose().mean.

namespace sextant {

template <class Backend>
typename Backend::State pose_mean_of(const Backend& backend) {
  if constexpr (requires { backend.pose_mean(); })
    return backend.pose_mean();
  else
    return backend.pose().mean;
}

}  // namespace sextant
