#pragma once
/// \file First-estimate Jacobians (Huang, Mourikis and Roumeliotis 2008, for landmarks): each
/// landmark's mean when it entered the map, by slot, and the step that evaluates an observation's H
/// there while its residual stays at the current estimate. Shared by the filters (EKF, SEIF).

#include <Eigen/Core>
#include <cstddef>
#include <vector>

#include "sextant/core/linearized_observation.hpp"

namespace sextant {

/// The landmarks' first means, stored by slot like the filters' current means.
template <int M>
class FirstLandmarkMeans {
 public:
  using Landmark = Eigen::Matrix<double, M, 1>;

  std::size_t size() const { return static_cast<std::size_t>(means_.size() / M); }
  Landmark at(std::size_t slot) const { return means_.template segment<M>(M * static_cast<Eigen::Index>(slot)); }

  void append(const Landmark& mean) {
    means_.conservativeResize(means_.size() + M);
    means_.template tail<M>() = mean;
  }
  /// The landmark store's removal: the last slot moves into the freed one.
  void move_last_into(std::size_t freed_slot) {
    means_.template segment<M>(M * static_cast<Eigen::Index>(freed_slot)) = means_.template tail<M>();
    means_.conservativeResize(means_.size() - M);
  }
  /// Forgets the landmarks from slot `count` on (a rolled-back transaction that added them).
  void truncate(std::size_t count) { means_.conservativeResize(M * static_cast<Eigen::Index>(count)); }

 private:
  Eigen::VectorXd means_;
};

/// Replaces lin's H with the one at the landmark's first estimate `first`; the residual stays the
/// one at the current estimate. Where the model cannot predict from the first estimate (e.g.
/// behind the camera from here), H stays current.
template <class Sensor, class State, class Landmark, class Measurement, int Z, int X, int M>
void use_first_estimate_jacobians(const Sensor& sensor, const State& x, const Landmark& first, const Measurement& z,
                                  LinearizedObservation<Z, X, M>& lin) {
  std::vector<LandmarkId> unusable_from_first;
  const auto at_first = linearize_if_observable(sensor, x, first, z, lin.id, lin.offset, unusable_from_first);
  if (!at_first) return;
  lin.J_z_x = at_first->J_z_x;
  lin.J_z_m = at_first->J_z_m;
}

}  // namespace sextant
