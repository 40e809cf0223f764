#pragma once
/// \file Block-sparse assembly of blocks of any size at any place: dense blocks written into a sparse
/// matrix at (row, col), entries that meet summed (Eigen's setFromTriplets), in the order the blocks
/// were added. SEIF's information matrix and the pose graph's chordal start are assembled with it;
/// GraphSLAM writes its systems itself, the same matrices as through this assembly: the reduced one
/// through core/block_sum.hpp (fixed-size blocks summed on a grid), the whole one through
/// core/block_columns.hpp (blocks whose places it knows column by column).

#include <Eigen/SparseCore>
#include <vector>

namespace sextant {

class BlockTriplets {
 public:
  /// block at rows [row, row + block.rows()), columns [col, col + block.cols()).
  template <class Block>
  void add(Eigen::Index row, Eigen::Index col, const Block& block) {
    for (Eigen::Index c = 0; c < block.cols(); ++c)
      for (Eigen::Index r = 0; r < block.rows(); ++r) triplets_.emplace_back(row + r, col + c, block(r, c));
  }
  /// block at (row, col) and its transpose at (col, row): an off-diagonal block of a symmetric matrix.
  template <class Block>
  void add_symmetric(Eigen::Index row, Eigen::Index col, const Block& block) {
    add(row, col, block);
    add(col, row, block.transpose());
  }
  void reserve(std::size_t entries) { triplets_.reserve(entries); }
  Eigen::SparseMatrix<double> to_sparse(Eigen::Index rows, Eigen::Index cols) const {
    Eigen::SparseMatrix<double> out(rows, cols);
    out.setFromTriplets(triplets_.begin(), triplets_.end());
    return out;
  }

 private:
  std::vector<Eigen::Triplet<double>> triplets_;
};

}  // namespace sextant
