#include "sextant/core/dense_slot_map.hpp"

#include <gtest/gtest.h>

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

TEST(DenseSlotMap, BehavesAsAMapUnderRandomInsertsErasesAndRekeys) {
  // Keys from a small range so that erases hit, probe runs collide and wrap around the table, and
  // the table grows several times; every operation is checked against std::map.
  std::mt19937 rng(7);
  DenseSlotMap<double> map;
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

TEST(DenseSlotMap, EntriesCanBeChangedInPlace) {
  DenseSlotMap<double> map;
  for (std::size_t k = 0; k < 100; ++k) map.try_emplace(k * 1000003, 1.0);
  for (auto& [key, value] : map) value += static_cast<double>(key);
  for (std::size_t k = 0; k < 100; ++k) EXPECT_EQ(map.find(k * 1000003)->second, 1.0 + static_cast<double>(k * 1000003));
}

}  // namespace
}  // namespace sextant
