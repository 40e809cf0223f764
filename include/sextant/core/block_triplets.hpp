#pragma once
/// \file Block-sparse assembly of blocks of any size at any place: dense blocks written into a sparse
/// matrix at (row, col), entries that meet summed (Eigen's setFromTriplets), in the order the blocks
/// were added. GraphSLAM's normal equations and SEIF's information matrix are assembled with it;
/// GraphSLAM's reduced system, fixed-size blocks on a grid, goes through core/block_sum.hpp, which
/// sums them first and writes the matrix itself (the same matrix as through this assembly).

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
