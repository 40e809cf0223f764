#pragma once
/// \file A square scratch matrix reused from step to step: view(d) hands out the top-left d x d
/// corner of one buffer that grows (by at least a quarter) only when d exceeds it. A filter step
/// that factorizes a dense block of varying size (SEIF's robot-and-active block, ~800 dimensions at
/// the thesis's scale) then allocates, and page-faults, a few times in a run instead of every step.
/// Copies start empty: scratch is not state.

#include <Eigen/Core>
#include <algorithm>

namespace sextant {

class SquareWorkspace {
 public:
  SquareWorkspace() = default;
  SquareWorkspace(const SquareWorkspace&) {}
  SquareWorkspace& operator=(const SquareWorkspace&) { return *this; }
  SquareWorkspace(SquareWorkspace&&) noexcept = default;
  SquareWorkspace& operator=(SquareWorkspace&&) noexcept = default;
  ~SquareWorkspace() = default;

  /// The d x d view; its contents are unspecified. Views handed out before are invalidated when
  /// the buffer grows.
  Eigen::Block<Eigen::MatrixXd> view(Eigen::Index d) {
    if (d > buffer_.rows()) {
      const Eigen::Index capacity = std::max(d, buffer_.rows() + buffer_.rows() / 4);
      buffer_.resize(capacity, capacity);
    }
    return buffer_.topLeftCorner(d, d);
  }
  /// Heap bytes held.
  std::size_t memory_bytes() const { return static_cast<std::size_t>(buffer_.size()) * sizeof(double); }

 private:
  Eigen::MatrixXd buffer_;
};

}  // namespace sextant
