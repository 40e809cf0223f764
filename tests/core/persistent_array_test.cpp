#include "sextant/core/persistent_array.hpp"

#include <gtest/gtest.h>

#include <random>
#include <vector>

namespace sextant {
namespace {

TEST(PersistentArray, BehavesAsAnArray) {
  PersistentArray<int> a;
  for (int i = 0; i < 1000; ++i) a.push_back(i * i);
  ASSERT_EQ(a.size(), 1000u);
  for (int i = 0; i < 1000; ++i) EXPECT_EQ(a[i], i * i);
  a.set(517, -1);
  EXPECT_EQ(a[517], -1);
  EXPECT_EQ(a[516], 516 * 516);
}

TEST(PersistentArray, CopiesAreIndependentValues) {
  // The shared-map bug of naive particle filters: after resampling, particles that share a map
  // must not see each other's landmark updates.
  PersistentArray<double> original;
  for (int i = 0; i < 100; ++i) original.push_back(i);
  std::vector<PersistentArray<double>> particles(5, original);  // "resampled" copies
  EXPECT_TRUE(particles[0].shares_storage_with(particles[4]));
  particles[2].set(42, 1000.0);
  particles[2].push_back(7.0);
  EXPECT_EQ(particles[2][42], 1000.0);
  for (int p : {0, 1, 3, 4}) {
    EXPECT_EQ(particles[p][42], 42.0) << p;
    EXPECT_EQ(particles[p].size(), 100u) << p;
  }
  EXPECT_EQ(original[42], 42.0);
  EXPECT_FALSE(particles[2].shares_storage_with(particles[3]));
}

TEST(PersistentArray, MatchesAVectorUnderRandomCopiesAndWrites) {
  std::mt19937 rng(5);
  std::vector<PersistentArray<int>> arrays(1);
  std::vector<std::vector<int>> reference(1);
  for (int step = 0; step < 5000; ++step) {
    const std::size_t k = rng() % arrays.size();
    switch (rng() % 4) {
      case 0:
        arrays.push_back(arrays[k]);
        reference.push_back(reference[k]);
        break;
      case 1:
        arrays[k].push_back(step);
        reference[k].push_back(step);
        break;
      default:
        if (!reference[k].empty()) {
          const std::size_t i = rng() % reference[k].size();
          arrays[k].set(i, -step);
          reference[k][i] = -step;
        }
    }
  }
  for (std::size_t k = 0; k < arrays.size(); ++k) {
    ASSERT_EQ(arrays[k].size(), reference[k].size());
    for (std::size_t i = 0; i < reference[k].size(); ++i) ASSERT_EQ(arrays[k][i], reference[k][i]);
  }
}

}  // namespace
}  // namespace sextant
