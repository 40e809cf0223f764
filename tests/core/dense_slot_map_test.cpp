#include "sextant/core/dense_slot_map.hpp"

#include "sextant/core/huge_page_arena.hpp"
#include "sextant/core/link_rows.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <map>
#include <random>

namespace sextant {
namespace {

/// The map's contents as an ordered map, to compare with the reference whatever the iteration order.
std::map<std::size_t, double> contents(const DenseSlotMap<double>& map) {
  std::map<std::size_t, double> out;
  for (const auto& [key, value] : map) EXPECT_TRUE(out.emplace(key, value).second) << "key " << key << " twice";
  return out;
}

/// Keys from a small range so that erases hit, probe runs collide and wrap around the table, and
/// the table grows several times; every operation is checked against std::map.
void check_against_std_map(DenseSlotMap<double>& map) {
  std::mt19937 rng(7);
  std::map<std::size_t, double> reference;
  std::uniform_int_distribution<std::size_t> key(0, 300);
  std::uniform_int_distribution<int> operation(0, 9);
  for (int step = 0; step < 20000; ++step) {
    const std::size_t k = key(rng);
    const double value = step;
    switch (operation(rng)) {
      case 0: case 1: case 2: {
        const auto [it, inserted] = map.try_emplace(k, value);
        const auto [ref, ref_inserted] = reference.try_emplace(k, value);
        ASSERT_EQ(inserted, ref_inserted);
        ASSERT_EQ(it->first, k);
        ASSERT_EQ(it->second, ref->second);
        break;
      }
      case 3: map.insert_or_assign(k, value); reference.insert_or_assign(k, value); break;
      case 4: case 5: ASSERT_EQ(map.erase(k), reference.erase(k)); break;
      case 6: {
        const std::size_t to = key(rng) + 301;  // a key that is never present
        if (reference.contains(to)) break;
        map.rekey(k, to);
        if (const auto node = reference.extract(k); !node.empty()) reference.emplace(to, node.mapped());
        break;
      }
      default: {
        const auto it = map.find(k);
        ASSERT_EQ(it != map.end(), reference.contains(k));
        ASSERT_EQ(map.contains(k), reference.contains(k));
        if (it != map.end()) ASSERT_EQ(it->second, reference.at(k));
      }
    }
    ASSERT_EQ(map.size(), reference.size());
    if (step % 500 == 0) ASSERT_EQ(contents(map), reference) << "step " << step;
  }
  EXPECT_EQ(contents(map), reference);
  map.clear();
  EXPECT_TRUE(map.empty());
  EXPECT_FALSE(map.contains(0));
  EXPECT_TRUE(map.try_emplace(0, 1.0).second);
}

TEST(DenseSlotMap, BehavesAsAMapUnderRandomInsertsErasesAndRekeys) {
  DenseSlotMap<double> map;
  check_against_std_map(map);
}

TEST(DenseSlotMap, BehavesAsAMapInAnArenaAndCopiesOutOfIt) {
  HugePageArena arena;
  DenseSlotMap<double> map(&arena);
  check_against_std_map(map);
  EXPECT_GT(arena.bytes_carved(), 0u);
  map.try_emplace(5, 2.0);
  const DenseSlotMap<double> heap_copy = map;  // the default resource, as any std::pmr container's
  HugePageArena other;
  const DenseSlotMap<double> arena_copy(map, &other);
  map.clear();
  map.try_emplace(6, 3.0);
  for (const DenseSlotMap<double>* copy : {&heap_copy, &arena_copy}) {
    EXPECT_EQ(copy->size(), 2u);
    EXPECT_EQ(copy->find(5)->second, 2.0);
    EXPECT_FALSE(copy->contains(6));
  }
}

TEST(HugePageArena, ReusesAFreedBlockForTheNextRequestOfItsSize) {
  HugePageArena arena;
  void* a = arena.allocate(80 * 1024, 8);
  void* b = arena.allocate(80 * 1024, 8);
  EXPECT_NE(a, b);
  EXPECT_EQ(arena.bytes_carved(), 2u * 80 * 1024);
  arena.deallocate(a, 80 * 1024, 8);
  void* small = arena.allocate(40, 8);  // another size: carved, not the freed block
  EXPECT_NE(small, a);
  EXPECT_EQ(arena.allocate(80 * 1024, 8), a);
  EXPECT_EQ(arena.bytes_carved(), 2u * 80 * 1024 + 48);  // 40 rounded up to 16
  void* wide = arena.allocate(64, 256);  // alignment beyond max_align_t: from the default heap
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(wide) % 256, 0u);
  arena.deallocate(wide, 64, 256);
  void* large = arena.allocate(std::size_t{100} << 20, 16);  // larger than any chunk: a chunk of its own
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(large) % HugePageMemory::kHugePage, 0u);
  static_cast<char*>(large)[(std::size_t{100} << 20) - 1] = 1;
}

TEST(LinkRows, CopiesIntoAnArenaOfTheirOwnAndMovesTheirs) {
  LinkRows<DenseSlotMap<double>> rows;
  for (std::size_t i = 0; i < 3; ++i) rows.append();
  for (std::size_t k = 0; k < 500; ++k) rows[k % 3].try_emplace(k, static_cast<double>(k));
  auto copy = std::make_unique<LinkRows<DenseSlotMap<double>>>(rows);
  LinkRows<DenseSlotMap<double>> moved = std::move(rows);
  copy->truncate(2);
  moved[1].try_emplace(10000, 1.0);
  EXPECT_EQ(copy->size(), 2u);
  EXPECT_EQ((*copy)[1].size(), 167u);
  EXPECT_EQ(moved[1].size(), 168u);
  moved = *copy;  // copy-assignment frees the moved rows into their arena, then drops it
  copy.reset();
  EXPECT_EQ(moved.size(), 2u);
  EXPECT_EQ(moved[0].find(3)->second, 3.0);
  rows.append();  // a moved-from LinkRows gets a new arena
  rows[0].try_emplace(1, 1.0);
  EXPECT_EQ(rows.size(), 1u);
  EXPECT_GT(rows.memory_bytes(), 0u);
}

TEST(DenseSlotMap, EntriesCanBeChangedInPlace) {
  DenseSlotMap<double> map;
  for (std::size_t k = 0; k < 100; ++k) map.try_emplace(k * 1000003, 1.0);
  for (auto& [key, value] : map) value += static_cast<double>(key);
  for (std::size_t k = 0; k < 100; ++k) EXPECT_EQ(map.find(k * 1000003)->second, 1.0 + static_cast<double>(k * 1000003));
}

}  // namespace
}  // namespace sextant
