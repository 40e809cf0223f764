#pragma once
/// \file A compressed column-major matrix written block column by block column from dense blocks
/// whose places the caller already knows in order, with no triplets and no sorting copy. GraphSLAM's
/// full system (poses and landmarks, thesis eqs. 58-64) has ~4.5 M entries on the default globe: as
/// triplets (16 bytes each) and Eigen's row-major copy in setFromTriplets they were 53% of a global
/// update's fresh pages (docs/benchmarks.md, "GraphSLAM's full system without triplets").
///
/// Blocks that meet at one place are summed in the order given, the order setFromTriplets sums
/// duplicate entries in: the matrix is bit for bit the one BlockTriplets builds from the same blocks.

#include <Eigen/SparseCore>
#include <span>

namespace sextant {

/// One dense block of a block column: `height` rows from matrix row `row`, its entry (r, c) at
/// data[r + height c] (column-major), or at data[c + width r] when `transposed` (the block is the
/// transpose of a column-major width x height block).
struct ColumnBlock {
  Eigen::Index row;
  int height;
  const double* data;
  bool transposed = false;

  double at(int r, int c, int width) const { return transposed ? data[c + width * r] : data[r + height * c]; }
};

class BlockColumnWriter {
 public:
  using StorageIndex = Eigen::SparseMatrix<double>::StorageIndex;

  /// The entries a block column of `width` columns with these blocks (sorted by row, blocks of one
  /// place next to each other) holds.
  static Eigen::Index entries(int width, std::span<const ColumnBlock> blocks) {
    Eigen::Index rows = 0;
    for (std::size_t k = 0; k < blocks.size(); ++k)
      if (k == 0 || blocks[k].row != blocks[k - 1].row) rows += blocks[k].height;
    return rows * width;
  }

  /// A rows x cols matrix of exactly `nonzeros` entries, to be written from column 0 on.
  BlockColumnWriter(Eigen::Index rows, Eigen::Index cols, Eigen::Index nonzeros) : out_(rows, cols) {
    out_.resizeNonZeros(nonzeros);
  }

  /// Writes the next `width` columns: the blocks sorted by row, those at one place next to each other
  /// (summed in the order given).
  void write(int width, std::span<const ColumnBlock> blocks) {
    StorageIndex* inner = out_.innerIndexPtr();
    double* value = out_.valuePtr();
    for (int c = 0; c < width; ++c) {
      out_.outerIndexPtr()[column_++] = static_cast<StorageIndex>(at_);
      for (std::size_t k = 0; k < blocks.size();) {
        const ColumnBlock& first = blocks[k];
        std::size_t end = k + 1;
        while (end < blocks.size() && blocks[end].row == first.row) ++end;
        if (end == k + 1)
          write_lone_column(first, c, width);
        else
          for (int r = 0; r < first.height; ++r) {
            double sum = first.at(r, c, width);
            for (std::size_t d = k + 1; d < end; ++d) sum += blocks[d].at(r, c, width);
            inner[at_] = static_cast<StorageIndex>(first.row + r);
            value[at_++] = sum;
          }
        k = end;
      }
    }
  }

  /// The matrix, once every column is written.
  Eigen::SparseMatrix<double> finish() {
    out_.outerIndexPtr()[column_] = static_cast<StorageIndex>(at_);
    eigen_assert(column_ == out_.cols() && at_ == out_.data().size() && "every column written, every entry filled");
    Eigen::SparseMatrix<double> out;  // swapped out: Eigen 3.4's SparseMatrix has no move constructor (a
    out.swap(out_);                   // member returned by std::move is copied)
    return out;
  }

 private:
  /// Column c of a block alone at its place (most blocks): a copy with one stride, chosen once per
  /// column instead of per entry, and nothing to sum.
  void write_lone_column(const ColumnBlock& block, int c, int width) {
    const Eigen::Index stride = block.transposed ? width : 1;
    const double* from = block.data + (block.transposed ? c : static_cast<Eigen::Index>(block.height) * c);
    StorageIndex* inner = out_.innerIndexPtr() + at_;
    double* value = out_.valuePtr() + at_;
    for (int r = 0; r < block.height; ++r) {
      inner[r] = static_cast<StorageIndex>(block.row + r);
      value[r] = from[stride * r];
    }
    at_ += block.height;
  }

  Eigen::SparseMatrix<double> out_;
  Eigen::Index column_ = 0;
  Eigen::Index at_ = 0;
};

}  // namespace sextant
