#pragma once
/// \file A scratch matrix reused from step to step: view(rows, cols) hands out the top-left corner
/// of one buffer that grows (each dimension by at least a quarter) only when a view exceeds it. A
/// step that works on a dense block of varying size (SEIF's robot-and-active block, ~800 dimensions
/// at the thesis's scale; the trailing block of the incremental GraphSLAM's profile Cholesky; the
/// fixed-lag window's normal equations and factor) then allocates, and page-faults, a few times in a
/// run instead of every step. Copies start empty: scratch is not state. From 2 MB on the buffer is
/// backed by huge pages (core/huge_pages.hpp): a block's 3 x 3 sub-blocks are read across columns a
/// few KB apart, one 4 KB page each, which in a virtual machine was a TLB miss each.

#include <Eigen/Core>
#include <algorithm>
#include <utility>

#include "sextant/core/huge_pages.hpp"

namespace sextant {

class MatrixWorkspace {
 public:
  MatrixWorkspace() = default;
  MatrixWorkspace(const MatrixWorkspace&) {}
  MatrixWorkspace& operator=(const MatrixWorkspace&) { return *this; }
  /// A moved-from workspace is empty (its capacity goes with the buffer).
  MatrixWorkspace(MatrixWorkspace&& other) noexcept
      : buffer_(std::move(other.buffer_)),
        row_capacity_(std::exchange(other.row_capacity_, 0)),
        col_capacity_(std::exchange(other.col_capacity_, 0)) {}
  MatrixWorkspace& operator=(MatrixWorkspace&& other) noexcept {
    buffer_ = std::move(other.buffer_);
    row_capacity_ = std::exchange(other.row_capacity_, 0);
    col_capacity_ = std::exchange(other.col_capacity_, 0);
    return *this;
  }
  ~MatrixWorkspace() = default;

  using View = Eigen::Map<Eigen::MatrixXd, 0, Eigen::OuterStride<>>;

  /// The rows x cols view (column stride: the row capacity); its contents are unspecified. Views
  /// handed out before are invalidated when the buffer grows.
  View view(Eigen::Index rows, Eigen::Index cols) {
    if (rows == 0 || cols == 0) return View(nullptr, rows, cols, Eigen::OuterStride<>(std::max<Eigen::Index>(rows, 1)));
    if (rows > row_capacity_ || cols > col_capacity_) {
      const Eigen::Index row_capacity = grown(row_capacity_, rows), col_capacity = grown(col_capacity_, cols);
      buffer_ = HugePageMemory(static_cast<std::size_t>(row_capacity * col_capacity) * sizeof(double));
      row_capacity_ = row_capacity;
      col_capacity_ = col_capacity;
    }
    return View(reinterpret_cast<double*>(buffer_.data()), rows, cols, Eigen::OuterStride<>(row_capacity_));
  }
  /// The d x d view.
  View view(Eigen::Index d) { return view(d, d); }
  /// Heap bytes held.
  std::size_t memory_bytes() const { return buffer_.size(); }

 private:
  /// A capacity that holds `needed`, by at least a quarter more than `capacity` when it grows.
  static Eigen::Index grown(Eigen::Index capacity, Eigen::Index needed) {
    return needed > capacity ? std::max(needed, capacity + capacity / 4) : capacity;
  }

  HugePageMemory buffer_;
  Eigen::Index row_capacity_ = 0, col_capacity_ = 0;
};

}  // namespace sextant
