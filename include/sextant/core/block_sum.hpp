#pragma once
/// \file Fixed-size blocks summed where they meet on a block grid before they become a sparse matrix. A
/// landmark seen from k poses adds k^2 blocks to GraphSLAM's reduced system (thesis eq. 68); as
/// triplets that is 36 k^2 entries of 16 bytes each (1-2 GB on a visual-inertial log of 1105 frames),
/// whose allocation and first touch cost more than the factorization. Summed here, each block of the
/// grid is one dense block, written once into the compressed matrix.
///
/// Each block's contributions are summed in the order they were added, which is the order
/// setFromTriplets sums duplicate entries in: the matrix is the one BlockTriplets builds from every
/// contribution, bit for bit.
///
/// Its index is a std::unordered_map beside the vector of sums, not core/dense_slot_map.hpp's map
/// (which holds SEIF's 3 x 3 links): built on that map, bit for bit the same and with its memory
/// kept from one solve to the next, `BM_GlobeGraphOneGlobalUpdate` was 1.16x slower (2026-12-06,
/// four pairs against the tree, g++, one pinned core; 1.25x without the memory kept), likely because
/// that map compares the keys stored in its entries, 1.2 KB apart with 12 x 12 blocks (not profiled).
/// Nor is this sum kept by GraphSlam between solves (clear() keeping the vector's capacity): that was
/// 1.06x slower over five pairs the same evening. A solve builds its sum anew.

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <algorithm>
#include <cstdint>
#include <numeric>
#include <stdexcept>
#include <tuple>
#include <unordered_map>
#include <vector>

#include "sextant/core/block_columns.hpp"

namespace sextant {

template <int Rows, int Cols = Rows>
class BlockSum {
 public:
  using Block = Eigen::Matrix<double, Rows, Cols>;

  /// Adds `block` at block row i, block column j (matrix rows [Rows i, Rows i + Rows)).
  template <class Other>
  void add(std::size_t i, std::size_t j, const Other& block) {
    const auto [at, inserted] = index_.try_emplace(key(i, j), blocks_.size());
    if (inserted)
      blocks_.push_back({i, j, block});
    else
      blocks_[at->second].sum += block;
  }
  /// block at (i, j) and its transpose at (j, i): an off-diagonal block of a symmetric matrix.
  template <class Other>
  void add_symmetric(std::size_t i, std::size_t j, const Other& block) {
    add(i, j, block);
    add(j, i, block.transpose());
  }

  std::size_t blocks() const { return blocks_.size(); }

  /// The sum as a compressed column-major matrix, written block column by block column by
  /// core/block_columns.hpp's writer (GraphSLAM's full system's, each block alone at its place): the
  /// matrix BlockTriplets::to_sparse builds from the summed blocks (each entry once, so nothing is
  /// summed there), without its triplets and row-major copy. At the thesis's globe scale the reduced
  /// system has ~2 M entries, and those two buffers (~56 MB a solve, allocated afresh) cost a virtual
  /// machine that backs fresh pages slowly more than the solve's arithmetic (docs/benchmarks.md,
  /// "GraphSLAM's reduced system without triplets").
  Eigen::SparseMatrix<double> to_sparse(Eigen::Index rows, Eigen::Index cols) const {
    eigen_assert(cols % Cols == 0 && "whole block columns");
    std::vector<std::size_t> order(blocks_.size());  // by block column, then block row
    std::iota(order.begin(), order.end(), std::size_t{0});
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
      return std::tie(blocks_[a].j, blocks_[a].i) < std::tie(blocks_[b].j, blocks_[b].i);
    });
    BlockColumnWriter out(rows, cols, Rows * Cols * static_cast<Eigen::Index>(blocks_.size()));
    std::vector<ColumnBlock> column;
    auto next = order.begin();
    for (std::size_t j = 0; static_cast<Eigen::Index>(Cols * j) < cols; ++j) {
      column.clear();
      for (; next != order.end() && blocks_[*next].j == j; ++next)
        column.push_back({Rows * static_cast<Eigen::Index>(blocks_[*next].i), Rows, blocks_[*next].sum.data()});
      out.write(Cols, column);
    }
    if (next != order.end()) throw std::out_of_range("BlockSum::to_sparse: a block lies beyond the matrix's columns");
    return out.finish();
  }

 private:
  struct Entry {
    std::size_t i, j;
    Block sum;
  };
  static std::uint64_t key(std::size_t i, std::size_t j) { return (static_cast<std::uint64_t>(i) << 32) | j; }

  std::unordered_map<std::uint64_t, std::size_t> index_;  ///< (i, j) -> its entry in blocks_
  std::vector<Entry> blocks_;                               ///< in the order first added
};

}  // namespace sextant
