#include "sextant/core/block_columns.hpp"

#include <gtest/gtest.h>

#include <Eigen/SparseCore>
#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "sextant/core/block_triplets.hpp"
#include "support/sparse_bit_identical.hpp"

namespace sextant {
namespace {

/// A symmetric matrix on a grid of 30 variables of 4 rows ("poses") followed by 50 of 3 ("landmarks"),
/// as GraphSLAM's full system: diagonal blocks, pose-pose and pose-landmark links, many links met more
/// than once, values over twelve decades (a sum in another order lands on other bits).
constexpr int kPoses = 30, kLandmarks = 50, P = 4, L = 3;
constexpr Eigen::Index kDim = P * kPoses + L * kLandmarks;

Eigen::Index offset(int variable) { return variable < kPoses ? P * variable : P * kPoses + L * (variable - kPoses); }
int height(int variable) { return variable < kPoses ? P : L; }

struct Link {
  int a, b;  ///< a < b
  Eigen::MatrixXd block;  ///< height(a) x height(b)
};

struct System {
  std::vector<Eigen::MatrixXd> diagonal;
  std::vector<Link> links;
};

System random_system(std::mt19937& rng) {
  std::uniform_real_distribution<double> mantissa(-1.0, 1.0), decade(-6.0, 6.0);
  auto random = [&](int rows, int cols) {
    return Eigen::MatrixXd(Eigen::MatrixXd::NullaryExpr(rows, cols, [&] { return mantissa(rng) * std::pow(10.0, decade(rng)); }));
  };
  System out;
  for (int v = 0; v < kPoses + kLandmarks; ++v) {
    const Eigen::MatrixXd half = random(height(v), height(v));
    out.diagonal.push_back(half + half.transpose());
  }
  std::uniform_int_distribution<int> pose(0, kPoses - 1), landmark(kPoses, kPoses + kLandmarks - 1);
  for (int k = 0; k < 400; ++k) {
    const int a = pose(rng), b = k % 2 ? landmark(rng) : std::min(kPoses - 1, a + 1 + pose(rng) % 3);
    if (a != b) out.links.push_back({a, b, random(height(a), height(b))});
  }
  return out;
}

Eigen::SparseMatrix<double> by_triplets(const System& system, bool both) {
  BlockTriplets triplets;
  for (int v = 0; v < kPoses + kLandmarks; ++v) triplets.add(offset(v), offset(v), system.diagonal[v]);
  for (const auto& link : system.links) {
    if (both) triplets.add(offset(link.a), offset(link.b), link.block);
    triplets.add(offset(link.b), offset(link.a), link.block.transpose());
  }
  return triplets.to_sparse(kDim, kDim);
}

/// The same blocks column by column: the diagonal, then the links, in the order given, each column's
/// blocks stably sorted by row.
Eigen::SparseMatrix<double> by_columns(const System& system, bool both) {
  std::vector<std::vector<ColumnBlock>> columns(kPoses + kLandmarks);
  for (int v = 0; v < kPoses + kLandmarks; ++v) columns[v].push_back({offset(v), height(v), system.diagonal[v].data()});
  for (const auto& link : system.links) {
    if (both) columns[link.b].push_back({offset(link.a), height(link.a), link.block.data()});
    columns[link.a].push_back({offset(link.b), height(link.b), link.block.data(), true});
  }
  Eigen::Index nonzeros = 0;
  for (int v = 0; v < kPoses + kLandmarks; ++v) {
    std::stable_sort(columns[v].begin(), columns[v].end(), [](const auto& l, const auto& r) { return l.row < r.row; });
    nonzeros += BlockColumnWriter::entries(height(v), columns[v]);
  }
  BlockColumnWriter writer(kDim, kDim, nonzeros);
  for (int v = 0; v < kPoses + kLandmarks; ++v) writer.write(height(v), columns[v]);
  return writer.finish();
}

using test::bit_identical;

TEST(BlockColumnWriter, IsTheTripletAssemblyBitForBit) {
  std::mt19937 rng(11);
  const System system = random_system(rng);
  int repeated = 0;  // links met before: summed where they meet
  for (std::size_t k = 0; k < system.links.size(); ++k)
    repeated += std::any_of(system.links.begin(), system.links.begin() + k,
                            [&](const Link& l) { return l.a == system.links[k].a && l.b == system.links[k].b; });
  ASSERT_GT(repeated, 50);
  for (const bool both : {true, false}) {
    SCOPED_TRACE(both ? "both triangles" : "lower triangle");
    EXPECT_TRUE(bit_identical(by_columns(system, both), by_triplets(system, both)));
  }
  System reversed = system;  // the links summed in the other order: the test can tell
  std::reverse(reversed.links.begin(), reversed.links.end());
  EXPECT_TRUE(by_columns(reversed, true).isApprox(by_triplets(system, true), 1e-12));
  EXPECT_FALSE(bit_identical(by_columns(reversed, true), by_triplets(system, true)));
}

TEST(BlockColumnWriter, TheLowerTriangleIsWhatACholeskyOfTheLowerTriangleReads) {
  std::mt19937 rng(12);
  const System system = random_system(rng);
  const Eigen::MatrixXd both = by_columns(system, true), lower = by_columns(system, false);
  EXPECT_EQ(Eigen::MatrixXd(both.triangularView<Eigen::Lower>()), Eigen::MatrixXd(lower.triangularView<Eigen::Lower>()));
  EXPECT_EQ(both, Eigen::MatrixXd(both.transpose())) << "both triangles: symmetric";
}

}  // namespace
}  // namespace sextant
