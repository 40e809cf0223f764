#pragma once
/// \file A square scratch matrix reused from step to step: view(d) hands out the top-left d x d
/// corner of one buffer that grows (by at least a quarter) only when d exceeds it. A filter step
/// that factorizes a dense block of varying size (SEIF's robot-and-active block, ~800 dimensions at
/// the thesis's scale) then allocates, and page-faults, a few times in a run instead of every step.
/// Copies start empty: scratch is not state. From 2 MB on the buffer is backed by huge pages
/// (core/huge_pages.hpp): the block's 3 x 3 sub-blocks are read across columns a few KB apart, one
/// 4 KB page each, which in a virtual machine was a TLB miss each.

#include <Eigen/Core>
#include <algorithm>
#include <utility>

#include "sextant/core/huge_pages.hpp"

namespace sextant {

class SquareWorkspace {
 public:
  SquareWorkspace() = default;
  SquareWorkspace(const SquareWorkspace&) {}
  SquareWorkspace& operator=(const SquareWorkspace&) { return *this; }
  /// A moved-from workspace is empty (its capacity goes with the buffer).
  SquareWorkspace(SquareWorkspace&& other) noexcept
      : buffer_(std::move(other.buffer_)), capacity_(std::exchange(other.capacity_, 0)) {}
  SquareWorkspace& operator=(SquareWorkspace&& other) noexcept {
    buffer_ = std::move(other.buffer_);
    capacity_ = std::exchange(other.capacity_, 0);
    return *this;
  }
  ~SquareWorkspace() = default;

  using View = Eigen::Map<Eigen::MatrixXd, 0, Eigen::OuterStride<>>;

  /// The d x d view (column stride: the capacity); its contents are unspecified. Views handed out
  /// before are invalidated when the buffer grows.
  View view(Eigen::Index d) {
    if (d > capacity_) {
      const Eigen::Index capacity = std::max(d, capacity_ + capacity_ / 4);
      buffer_ = HugePageMemory(static_cast<std::size_t>(capacity * capacity) * sizeof(double));
      capacity_ = capacity;
    }
    return View(reinterpret_cast<double*>(buffer_.data()), d, d, Eigen::OuterStride<>(capacity_));
  }
  /// Heap bytes held.
  std::size_t memory_bytes() const { return buffer_.size(); }

 private:
  HugePageMemory buffer_;
  Eigen::Index capacity_ = 0;
};

}  // namespace sextant
