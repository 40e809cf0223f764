#pragma once
/// \file Symmetric dense matrix kernels: blocks read from the lower triangle, mirroring, and a
/// square matrix whose size grows with amortized O(1) reallocation (a map that grows by blocks).

#include <Eigen/Core>
#include <algorithm>

namespace sextant {

/// Copies the strictly lower triangle of a square matrix onto its strictly upper triangle,
/// in cache-friendly tiles.
template <class Derived>
void mirror_lower_to_upper(Eigen::MatrixBase<Derived>& a) {
  constexpr Eigen::Index kTile = 64;
  const Eigen::Index n = a.rows();
  for (Eigen::Index j0 = 0; j0 < n; j0 += kTile) {
    const Eigen::Index width = std::min(kTile, n - j0);
    for (Eigen::Index i0 = 0; i0 < j0; i0 += kTile) {
      const Eigen::Index height = std::min(kTile, j0 - i0);
      a.block(i0, j0, height, width) = a.block(j0, i0, width, height).transpose().eval();
    }
    for (Eigen::Index c = 0; c < width; ++c)
      for (Eigen::Index r = 0; r < c; ++r) a(j0 + r, j0 + c) = a(j0 + c, j0 + r);
  }
}

/// Columns [offset, offset + width) of a symmetric matrix of which only the lower triangle is
/// stored: rows above the block come from the transposed row block, the diagonal block is
/// completed from its lower half. O(n * width).
template <int Width, class Derived>
Eigen::Matrix<double, Eigen::Dynamic, Width> symmetric_column_block(const Eigen::MatrixBase<Derived>& lower,
                                                                     Eigen::Index offset) {
  const Eigen::Index n = lower.rows(), below = n - offset - Width;
  Eigen::Matrix<double, Eigen::Dynamic, Width> out(n, Width);
  out.topRows(offset) = lower.block(offset, 0, Width, offset).transpose();
  out.template middleRows<Width>(offset) =
      lower.template block<Width, Width>(offset, offset).template selfadjointView<Eigen::Lower>();
  out.bottomRows(below) = lower.block(offset + Width, offset, below, Width);
  return out;
}

/// The full symmetric diagonal block [offset, offset + Width)^2 from a lower-triangle matrix.
template <int Width, class Derived>
Eigen::Matrix<double, Width, Width> symmetric_diagonal_block(const Eigen::MatrixBase<Derived>& lower,
                                                             Eigen::Index offset) {
  return lower.template block<Width, Width>(offset, offset).template selfadjointView<Eigen::Lower>();
}

/// A square matrix of dimension dim() stored in a larger buffer; growing it by a block costs
/// amortized O(dim) per added row instead of a full reallocation each time.
class GrowableSquareMatrix {
 public:
  using Index = Eigen::Index;

  explicit GrowableSquareMatrix(Index dim = 0) : storage_(Eigen::MatrixXd::Zero(dim, dim)), dim_(dim) {}

  Index dim() const { return dim_; }
  auto view() { return storage_.topLeftCorner(dim_, dim_); }
  auto view() const { return storage_.topLeftCorner(dim_, dim_); }

  /// Makes room for a dimension of at least `dim` without reallocating later.
  void reserve(Index dim) {
    if (dim <= storage_.rows()) return;
    Eigen::MatrixXd bigger(dim, dim);
    bigger.topLeftCorner(dim_, dim_) = view();
    storage_.swap(bigger);
  }
  Index capacity() const { return storage_.rows(); }

  /// Appends `count` zero rows and columns; the buffer grows by half when full (at most 2.25x the
  /// memory of the matrix, amortized O(dim) per added row).
  void grow(Index count) {
    const Index needed = dim_ + count;
    if (needed > storage_.rows()) reserve(std::max(needed, storage_.rows() + storage_.rows() / 2));
    storage_.block(0, dim_, needed, count).setZero();
    storage_.block(dim_, 0, count, needed).setZero();
    dim_ = needed;
  }

  /// Removes the rows and columns [offset, offset + size) by moving the last `size` rows and
  /// columns into their place (marginalization of a Gaussian in moment form), then shrinks.
  void remove_block_by_moving_last(Index offset, Index size) {
    const Index last = dim_ - size;
    if (offset != last) {
      auto a = view();
      a.middleCols(offset, size) = a.middleCols(last, size).eval();
      a.middleRows(offset, size) = a.middleRows(last, size).eval();
    }
    dim_ = last;
  }

 private:
  Eigen::MatrixXd storage_;
  Index dim_;
};

}  // namespace sextant
