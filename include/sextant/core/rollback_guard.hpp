#pragma once
/// \file Copy-and-restore for the strong guarantee, where a step changes the state in several moves
/// that can each throw (the EKF's sequential updates, GraphSLAM's optimization): the guard copies
/// what it watches and, unless committed, moves the copies back when it goes out of scope, e.g. on
/// the way out of an exception. Where a step can compute everything first and commit at its end
/// (the EKF's batch update, SEIF, FastSLAM's transaction) that is cheaper and used instead.

#include <tuple>
#include <utility>

namespace sextant {

template <class... T>
class RollbackGuard {
 public:
  explicit RollbackGuard(T&... watched) : watched_(watched...), saved_(watched...) {}
  RollbackGuard(const RollbackGuard&) = delete;
  RollbackGuard& operator=(const RollbackGuard&) = delete;
  ~RollbackGuard() {
    if (!committed_) restore(std::index_sequence_for<T...>{});
  }
  /// Keeps the changes.
  void commit() { committed_ = true; }

 private:
  template <std::size_t... I>
  void restore(std::index_sequence<I...>) noexcept {
    ((std::get<I>(watched_) = std::move(std::get<I>(saved_))), ...);
  }

  std::tuple<T&...> watched_;
  std::tuple<T...> saved_;
  bool committed_ = false;
};

}  // namespace sextant
