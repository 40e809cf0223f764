#include "sextant/core/sparse_information.hpp"

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <cstdint>
#include <memory>
#include <map>
#include <random>
#include <vector>

#include "sextant/core/matrix_workspace.hpp"

namespace sextant {
namespace {

using Info = SparseInformation<2, 2>;
using Block = Info::LandmarkBlock;

/// A form with `n` landmarks, random diagonal blocks and links between a third of the pairs.
Info random_form(std::size_t n, std::mt19937& rng) {
  std::uniform_real_distribution<double> value(-1.0, 1.0);
  auto random_block = [&] { return Block(Block::NullaryExpr([&] { return value(rng); })); };
  Info info;
  for (std::size_t i = 0; i < n; ++i) {
    info.append_landmark();
    info.diagonal(i) = Block::Identity() * 10.0;
  }
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = i + 1; j < n; ++j)
      if (rng() % 3 == 0) info.add_to_link(i, j, random_block());
  return info;
}

/// Every change of a set of pairs, as the callers pass it: block (a, b) for positions a < b.
Eigen::MatrixXd random_changes(std::size_t count, std::mt19937& rng) {
  std::uniform_real_distribution<double> value(-1.0, 1.0);
  return Eigen::MatrixXd::NullaryExpr(2 * static_cast<Eigen::Index>(count), 2 * static_cast<Eigen::Index>(count),
                                      [&] { return value(rng); });
}

TEST(SparseInformation, AddToLinksIsAddToLinkPairByPairBitForBit) {
  // add_to_links writes one landmark's links at a time; the result must be what add_to_link gives
  // pair by pair, to the bit, for slots in any order (SEIF passes its queue order) and for pairs
  // that are linked already and pairs that are not. Each pair below the diagonal is reported once,
  // with its new block (SEIF's motion update builds the block it checks from them).
  std::mt19937 rng(11);
  const Info start = random_form(30, rng);
  for (int trial = 0; trial < 20; ++trial) {
    std::vector<std::size_t> slots(30);
    for (std::size_t i = 0; i < slots.size(); ++i) slots[i] = i;
    std::shuffle(slots.begin(), slots.end(), rng);
    slots.resize(5 + rng() % 20);
    const Eigen::MatrixXd changes = random_changes(slots.size(), rng);
    auto change = [&](std::size_t a, std::size_t b) { return Block(changes.block<2, 2>(2 * a, 2 * b)); };
    Info by_rows = start, by_pairs = start;
    std::map<std::pair<std::size_t, std::size_t>, Block> reported;  // the new blocks below the diagonal
    by_rows.add_to_links(slots, change, [&](std::size_t a, std::size_t b, const Block& block) {
      EXPECT_GT(a, b);
      EXPECT_TRUE(reported.emplace(std::pair(a, b), block).second) << "reported twice: " << a << ", " << b;
    });
    EXPECT_EQ(reported.size(), slots.size() * (slots.size() - 1) / 2);
    for (const auto& [pair, block] : reported) {
      EXPECT_EQ(block, by_rows.landmark_block(slots[pair.first], slots[pair.second])) << "trial " << trial;
      EXPECT_EQ(block, by_rows.landmark_block(slots[pair.second], slots[pair.first]).transpose()) << "trial " << trial;
    }
    for (std::size_t a = 0; a < slots.size(); ++a)
      for (std::size_t b = a + 1; b < slots.size(); ++b) by_pairs.add_to_link(slots[a], slots[b], change(a, b));
    EXPECT_EQ(Eigen::MatrixXd(by_rows.to_sparse()), Eigen::MatrixXd(by_pairs.to_sparse())) << "trial " << trial;
  }
}

TEST(SparseInformation, AddToLinksIsUndoneByRollback) {
  // Inside a transaction, with a landmark appended in it (its links are dropped with it) and pairs
  // that were not linked before (their links are erased again).
  std::mt19937 rng(12);
  Info info = random_form(15, rng);
  const Eigen::MatrixXd before = info.to_sparse();
  std::vector<std::size_t> link_counts;
  for (std::size_t i = 0; i < info.num_landmarks(); ++i) link_counts.push_back(info.links(i).size());
  info.begin_transaction();
  const std::size_t added = info.append_landmark();
  const std::vector<std::size_t> slots{7, added, 2, 11, 0, 14};
  const Eigen::MatrixXd changes = random_changes(slots.size(), rng);
  info.add_to_links(slots, [&](std::size_t a, std::size_t b) { return Block(changes.block<2, 2>(2 * a, 2 * b)); });
  EXPECT_NE(info.links(added).size(), 0u);
  info.rollback();
  EXPECT_EQ(Eigen::MatrixXd(info.to_sparse()), before);
  for (std::size_t i = 0; i < info.num_landmarks(); ++i) EXPECT_EQ(info.links(i).size(), link_counts[i]) << "slot " << i;
}

TEST(SparseInformation, ARowOfBlocksIsLandmarkBlockForEachSlot) {
  // Long enough that the look-ups are prefetched ahead (8 and 16 look-ups), with the row's own slot
  // (its diagonal block), linked and unlinked slots; and prefetching a map, empty or not, reads
  // nothing outside it (the sanitizer build runs this test).
  std::mt19937 rng(13);
  const Info info = random_form(40, rng);
  std::vector<std::size_t> slots(40);
  for (std::size_t i = 0; i < slots.size(); ++i) slots[i] = i;
  std::shuffle(slots.begin(), slots.end(), rng);
  for (const std::size_t row : {std::size_t{0}, std::size_t{17}, std::size_t{39}}) {
    std::size_t visited = 0;
    info.for_each_block_in_row(row, slots, [&](std::size_t b, const Block& block) {
      EXPECT_EQ(b, visited++);
      EXPECT_EQ(block, info.landmark_block(row, slots[b])) << "row " << row << ", slot " << slots[b];
    });
    EXPECT_EQ(visited, slots.size());
  }
  const DenseSlotMap<Block> empty;
  empty.prefetch_position(3);
  empty.prefetch_entry(3);
  for (std::size_t key = 0; key < 100; ++key) info.links(0).prefetch_entry(key);
}

/// Landmark-landmark links (each direction counted) and robot links of a form.
std::pair<std::size_t, std::size_t> total_links(const Info& info) {
  std::size_t links = 0;
  for (std::size_t i = 0; i < info.num_landmarks(); ++i) links += info.links(i).size();
  return {links, info.robot_links().size()};
}

TEST(SparseInformation, SaysWhetherMarginalizingASlotAddsLinks) {
  // Every slot of random forms, sparse and dense, some landmarks linked to the robot: the answer
  // against the links a marginalization leaves (no fill: exactly the slot's own links gone).
  std::mt19937 rng(5);
  std::size_t without_fill = 0, with_fill = 0;
  for (int form = 0; form < 40; ++form) {
    Info info = random_form(form % 2 == 0 ? 6 : 9, rng);
    if (form % 4 < 2)  // dense: most pairs linked, so that many slots have a clique around them
      for (std::size_t i = 0; i < info.num_landmarks(); ++i)
        for (std::size_t j = i + 1; j < info.num_landmarks(); ++j)
          if (rng() % 4 != 0) info.add_to_link(i, j, Block::Identity() * 0.1);
    for (std::size_t i = 0; i < info.num_landmarks(); ++i)
      if (rng() % 3 != 0) info.add_to_robot_link(i, Info::CrossBlock::Constant(0.1));
    for (std::size_t slot = 0; slot < info.num_landmarks(); ++slot) {
      Info copy = info;
      const auto [links, robot_links] = total_links(copy);
      const bool answer = copy.marginalizing_adds_no_links(slot);
      const std::size_t own = 2 * copy.links(slot).size(), own_robot = copy.is_linked_to_robot(slot) ? 1 : 0;
      copy.marginalize_landmark(slot);
      const auto [after, robot_after] = total_links(copy);
      EXPECT_EQ(answer, after == links - own && robot_after == robot_links - own_robot) << "form " << form << ", slot " << slot;
      (answer ? without_fill : with_fill) += 1;
    }
  }
  EXPECT_GT(without_fill, 20u);
  EXPECT_GT(with_fill, 20u);
}

TEST(SparseInformation, CopiesAndMovesKeepTheLinksWhoeverOwnedTheirMemory) {
  // The link maps live in an arena of their SparseInformation (core/link_rows.hpp): a copy must own
  // its own, outlive the original and not share changes with it; a move or a move-assignment over a
  // form with links of its own must keep the moved links and free the replaced ones (ASan and the
  // sanitized test run check the freeing).
  std::mt19937 rng(5);
  auto original = std::make_unique<Info>(random_form(40, rng));
  const Eigen::MatrixXd expected = Eigen::MatrixXd(original->to_sparse());
  Info copy = *original;
  Info assigned = random_form(10, rng);
  assigned = *original;
  original->add_to_link(0, 1, Block::Identity());
  original.reset();
  EXPECT_EQ(Eigen::MatrixXd(copy.to_sparse()), expected);
  EXPECT_EQ(Eigen::MatrixXd(assigned.to_sparse()), expected);
  Info moved = std::move(copy);
  Info replaced = random_form(25, rng);
  replaced = std::move(assigned);
  EXPECT_EQ(Eigen::MatrixXd(moved.to_sparse()), expected);
  EXPECT_EQ(Eigen::MatrixXd(replaced.to_sparse()), expected);
  for (std::size_t i = 0; i < 40; ++i) moved.add_to_link(i, (i + 7) % 40, Block::Identity());  // grows maps
  EXPECT_EQ(Eigen::MatrixXd(replaced.to_sparse()), expected);
}

TEST(MatrixWorkspace, HandsOutViewsOfOneBufferAndCopiesEmpty) {
  MatrixWorkspace workspace;
  auto small = workspace.view(10);
  EXPECT_EQ(small.rows(), 10);
  EXPECT_EQ(small.cols(), 10);
  const std::size_t bytes = workspace.memory_bytes();
  EXPECT_EQ(bytes, 832u);  // 100 doubles, rounded up to a cache line
  workspace.view(8);
  EXPECT_EQ(workspace.memory_bytes(), bytes);  // no reallocation for a smaller block
  workspace.view(11);
  EXPECT_EQ(workspace.memory_bytes(), 12 * 12 * sizeof(double));  // grows by a quarter at least
  const MatrixWorkspace copy = workspace;
  EXPECT_EQ(copy.memory_bytes(), 0u);  // scratch is not state
  // From 2 MB on: whole huge pages, aligned to one, the column stride the capacity.
  const auto large = workspace.view(600);
  EXPECT_EQ(workspace.memory_bytes(), 2 * HugePageMemory::kHugePage);  // 600^2 doubles = 2.9 MB
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(large.data()) % HugePageMemory::kHugePage, 0u);
  EXPECT_EQ(large.outerStride(), 600);
  MatrixWorkspace moved = std::move(workspace);  // the buffer and its capacity go together
  EXPECT_EQ(moved.memory_bytes(), 2 * HugePageMemory::kHugePage);
  EXPECT_EQ(workspace.memory_bytes(), 0u);
  EXPECT_EQ(workspace.view(20).outerStride(), 20);  // a moved-from workspace allocates afresh
  workspace.view(20).setZero();
  moved = std::move(workspace);
  EXPECT_EQ(moved.view(20).outerStride(), 20);
  EXPECT_EQ(workspace.view(30).outerStride(), 30);
  workspace.view(30).setZero();
  MatrixWorkspace wide;  // rectangular views: each dimension's capacity grows on its own
  EXPECT_EQ(wide.view(6, 0).cols(), 0);
  EXPECT_EQ(wide.memory_bytes(), 0u);  // an empty view allocates nothing
  EXPECT_EQ(wide.view(40, 3).outerStride(), 40);
  EXPECT_EQ(wide.memory_bytes(), 40 * 3 * sizeof(double));
  const auto wider = wide.view(10, 8);  // fewer rows, more columns: the row capacity stays
  EXPECT_EQ(wider.outerStride(), 40);
  EXPECT_EQ(wide.memory_bytes(), 40 * 8 * sizeof(double));
  wide.view(12, 5).setZero();
  EXPECT_EQ(wide.memory_bytes(), 40 * 8 * sizeof(double));
}

}  // namespace
}  // namespace sextant
