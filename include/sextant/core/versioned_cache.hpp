#pragma once
/// \file A value computed on demand from an estimator's state and kept until the state changes:
/// the estimator bumps a version on every change, get(version, make) recomputes when they differ.
/// Safe for const methods called from several threads at once (a mutex guards the slot; the
/// value is shared, so a reader keeps its copy alive while another thread replaces it). A move,
/// like any write to the estimator that holds the cache, must not race with its readers: it takes
/// the value without the lock and cannot throw.

#include <cstdint>
#include <memory>
#include <mutex>
#include <tuple>
#include <utility>

namespace sextant {

template <class T>
class VersionedCache {
 public:
  VersionedCache() = default;
  VersionedCache(const VersionedCache& other) { std::tie(value_, version_) = other.snapshot(); }
  VersionedCache& operator=(const VersionedCache& other) {
    if (this != &other) {
      auto [value, version] = other.snapshot();
      std::lock_guard lock(mutex_);
      value_ = std::move(value);
      version_ = version;
    }
    return *this;
  }
  VersionedCache(VersionedCache&& other) noexcept : value_(std::move(other.value_)), version_(other.version_) {}
  VersionedCache& operator=(VersionedCache&& other) noexcept {
    value_ = std::move(other.value_);
    version_ = other.version_;
    return *this;
  }

  /// The value for `version`: the cached one, or make() (called under the lock; it returns a
  /// std::shared_ptr<const T>, so T need not be movable) when stale.
  template <class Make>
  std::shared_ptr<const T> get(std::uint64_t version, Make&& make) const {
    std::lock_guard lock(mutex_);
    if (!value_ || version_ != version) {
      value_ = make();
      version_ = version;
    }
    return value_;
  }

 private:
  std::pair<std::shared_ptr<const T>, std::uint64_t> snapshot() const {
    std::lock_guard lock(mutex_);
    return {value_, version_};
  }

  mutable std::mutex mutex_;
  mutable std::shared_ptr<const T> value_;
  mutable std::uint64_t version_ = 0;
};

}  // namespace sextant
