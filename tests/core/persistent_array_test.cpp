#include "sextant/core/persistent_array.hpp"
#include "sextant/core/particle_path.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <span>
#include <tuple>
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

/// (step, pose, summed weight) of every pose walk_back visits, in the order it visits them.
std::vector<std::tuple<std::size_t, int, double>> walk(const std::vector<ParticlePath<int>>& cloud,
                                                       const std::vector<double>& weights) {
  std::vector<const ParticlePath<int>*> paths;
  for (const auto& path : cloud) paths.push_back(&path);
  std::vector<std::tuple<std::size_t, int, double>> out;
  ParticlePath<int>::walk_back(paths, weights, [&](std::size_t j, std::span<const ParticlePath<int>::WeightedPose> poses) {
    std::vector<std::pair<int, double>> sorted;  // walk_back's order of one step's poses is unspecified
    for (const auto& p : poses) sorted.emplace_back(*p.pose, p.weight);
    std::sort(sorted.begin(), sorted.end());
    for (const auto& [pose, weight] : sorted) out.emplace_back(j, pose, weight);
  });
  return out;
}

TEST(ParticlePath, CopiesShareTheirAncestorsAndWalkBackSumsTheWeightsOfPathsThatMeet) {
  // Three particles from one start; after step 1 particle 0 is resampled twice and particle 2 is
  // dropped, as a resampling would: the copies share poses 0 and 1 and part at step 2.
  std::vector<ParticlePath<int>> cloud(3);
  for (int i = 0; i < 3; ++i) cloud[i].push_back(0);  // one start pose each, but three paths
  for (int i = 0; i < 3; ++i) cloud[i].push_back(10 + i);
  cloud = {cloud[0], cloud[0], cloud[1]};
  for (int i = 0; i < 3; ++i) cloud[i].push_back(20 + i);
  cloud[2].replace_back(99);  // an update moved the last pose: same ancestors
  EXPECT_EQ(cloud[2].size(), 3u);
  EXPECT_EQ(cloud[2].back(), 99);
  const std::vector<std::tuple<std::size_t, int, double>> expected = {
      {2, 20, 0.5},  {2, 21, 0.25}, {2, 99, 0.25},  // three poses of today
      {1, 10, 0.75}, {1, 11, 0.25},                 // the two copies of particle 0 meet at step 1
      {0, 0, 0.25},  {0, 0, 0.75}};                 // equal values of two ancestors stay two poses
  EXPECT_EQ(walk(cloud, {0.5, 0.25, 0.25}), expected);
}

TEST(ParticlePath, WalkBackRefusesPathsOfDifferentLengthsAndMissingWeights) {
  std::vector<ParticlePath<int>> cloud(2);
  cloud[0].push_back(1);
  cloud[1].push_back(2);
  cloud[1].push_back(3);
  EXPECT_THROW(walk(cloud, {0.5, 0.5}), invalid_input_error);
  cloud[0].push_back(4);
  EXPECT_THROW(walk(cloud, {1.0}), invalid_input_error);
  EXPECT_EQ(walk(cloud, {0.5, 0.5}).size(), 4u);
}

TEST(ParticlePath, ALongPathIsReleasedWithoutRecursion) {
  // A path of 10^6 poses released by nested destructors would need ~10^6 stack frames: past any
  // thread's stack. ~Node releases it in a loop, also where a copy still holds the first half.
  ParticlePath<int> path;
  for (int i = 0; i < 500'000; ++i) path.push_back(i);
  ParticlePath<int> half = path;
  for (int i = 0; i < 500'000; ++i) path.push_back(i);
  path = ParticlePath<int>();
  EXPECT_EQ(half.size(), 500'000u);
  EXPECT_EQ(half.back(), 499'999);
  half = ParticlePath<int>();
  EXPECT_TRUE(half.empty());
}

}  // namespace
}  // namespace sextant
