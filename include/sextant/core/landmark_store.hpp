#pragma once
/// \file The landmark store of the back-ends with a stacked state (EKF, SEIF, GraphSLAM): ids to
/// dense slots (LandmarkPool), the current means stacked by slot, and each landmark's mean when it
/// entered the map (first-estimate Jacobians, core/first_estimates.hpp). Removal moves the last
/// slot into the freed one in all three, so slot k is landmark k everywhere.

#include <Eigen/Core>
#include <cstddef>
#include <span>
#include <utility>
#include <vector>

#include "sextant/core/landmark_pool.hpp"

namespace sextant {

/// Vectors of dimension M stacked by slot: (m_0, m_1, ...).
template <int M>
class StackedMeans {
 public:
  using Landmark = Eigen::Matrix<double, M, 1>;

  std::size_t size() const { return static_cast<std::size_t>(means_.size() / M); }
  Landmark at(std::size_t slot) const { return means_.template segment<M>(M * static_cast<Eigen::Index>(slot)); }
  auto slot(std::size_t s) { return means_.template segment<M>(M * static_cast<Eigen::Index>(s)); }
  /// All of them, one after the other (a correction adds its landmark part at once).
  Eigen::VectorXd& stacked() { return means_; }
  const Eigen::VectorXd& stacked() const { return means_; }

  void append(const Landmark& mean) {
    means_.conservativeResize(means_.size() + M);
    means_.template tail<M>() = mean;
  }
  /// The pool's removal: the last slot moves into the freed one.
  void move_last_into(std::size_t freed_slot) {
    means_.template segment<M>(M * static_cast<Eigen::Index>(freed_slot)) = means_.template tail<M>();
    means_.conservativeResize(means_.size() - M);
  }
  /// Forgets the slots from `count` on.
  void truncate(std::size_t count) { means_.conservativeResize(M * static_cast<Eigen::Index>(count)); }

 private:
  Eigen::VectorXd means_;
};

template <int M>
class LandmarkStore {
 public:
  using Landmark = Eigen::Matrix<double, M, 1>;

  /// Where slot `slot` starts in a state stacked as (robot of dimension X, landmarks).
  template <int X>
  static Eigen::Index offset_of(std::size_t slot) {
    return X + M * static_cast<Eigen::Index>(slot);
  }

  bool contains(LandmarkId id) const { return pool_.contains(id); }
  std::size_t size() const { return pool_.size(); }
  const std::vector<LandmarkId>& ids() const { return pool_.ids(); }
  LandmarkId id_at(std::size_t slot) const { return pool_.id_at(slot); }
  /// Throws unknown_landmark_error.
  std::size_t slot(LandmarkId id) const { return pool_.slot(id); }
  const LandmarkPool& pool() const { return pool_; }

  Landmark mean(std::size_t slot) const { return means_.at(slot); }
  Landmark first_mean(std::size_t slot) const { return first_means_.at(slot); }
  StackedMeans<M>& means() { return means_; }
  const StackedMeans<M>& means() const { return means_; }
  /// Every landmark's id and mean in slot order, O(n): a back-end's landmark_means().
  template <class Mean>
  std::vector<std::pair<LandmarkId, Landmark>> id_mean_pairs(Mean&& mean_at) const {
    std::vector<std::pair<LandmarkId, Landmark>> out;
    out.reserve(size());
    for (std::size_t slot = 0; slot < size(); ++slot) out.emplace_back(id_at(slot), mean_at(slot));
    return out;
  }

  /// Appends a landmark at `mean` (also its first mean); returns its slot. Throws
  /// duplicate_landmark_error, leaving the store as it was.
  std::size_t add(LandmarkId id, const Landmark& mean) {
    const std::size_t slot = pool_.add(id);
    means_.append(mean);
    first_means_.append(mean);
    return slot;
  }
  /// Removes a landmark: the last slot moves into the freed one. Throws unknown_landmark_error.
  LandmarkPool::Removal remove(LandmarkId id) {
    const auto removal = pool_.remove(id);
    means_.move_last_into(removal.freed_slot);
    first_means_.move_last_into(removal.freed_slot);
    return removal;
  }
  /// The means of `ids` (appended to `means`) and where each starts in a state stacked as (robot of
  /// dimension X, landmarks), in that order: the gather of a joint marginal. Throws unknown_landmark_error.
  template <int X, class Means>
  std::vector<Eigen::Index> gather(std::span<const LandmarkId> ids, Means& means) const {
    std::vector<Eigen::Index> offsets;
    for (const LandmarkId id : ids) {
      const std::size_t s = slot(id);
      means.push_back(mean(s));
      offsets.push_back(offset_of<X>(s));
    }
    return offsets;
  }
  /// Forgets the landmarks from slot `count` on (a rolled-back step that added them).
  void truncate(std::size_t count) {
    while (pool_.size() > count) pool_.remove(pool_.id_at(pool_.size() - 1));
    means_.truncate(count);
    first_means_.truncate(count);
  }

 private:
  LandmarkPool pool_;
  StackedMeans<M> means_;
  StackedMeans<M> first_means_;
};

}  // namespace sextant
