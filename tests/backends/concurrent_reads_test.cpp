// Thread safety (issue 15): const methods of one estimator called from several threads at once give
// what they give from one thread, and independent estimators in different threads do not disturb
// each other. Run under ThreadSanitizer by ./run.sh test-tsan, where any data race fails the test.
#include <gtest/gtest.h>

#include <thread>
#include <vector>

#include "sextant/backends/ekf_slam.hpp"
#include "sextant/backends/fast_slam.hpp"
#include "sextant/backends/graph_slam.hpp"
#include "sextant/backends/seif_slam.hpp"
#include "sextant/eval/runner.hpp"
#include "sextant/models/beacon_ship_2d.hpp"
#include "support/batch_least_squares.hpp"

namespace sextant {
namespace {

using test::kLinearMotion;
using test::kLinearPrior;
using test::kLinearSensor;

struct Ekf {
  static auto make() { return EkfSlam<BeaconShip2D, BeaconOffset2D>{kLinearMotion, kLinearSensor, kLinearPrior}; }
};
struct Seif {
  static auto make() {
    return SeifSlam<BeaconShip2D, BeaconOffset2D>{kLinearMotion, kLinearSensor, kLinearPrior, {.max_active = 3}};
  }
};
struct Graph {
  static auto make() { return GraphSlam<BeaconShip2D, BeaconOffset2D>{kLinearMotion, kLinearSensor, kLinearPrior}; }
};
struct Fast {
  static auto make() {
    return FastSlam<BeaconShip2D, BeaconOffset2D>{kLinearMotion, kLinearSensor, kLinearPrior, {.particles = 30}};
  }
};

/// Everything a reader can ask, as one comparable value.
template <class Estimator>
struct Reading {
  explicit Reading(const Estimator& e) : pose(e.pose()), map(e.map()), ids(e.landmark_ids()) {
    for (LandmarkId id : ids) landmarks.push_back(e.landmark(id));
  }
  bool operator==(const Reading& o) const {
    auto same = [](const auto& a, const auto& b) { return a.id == b.id && a.mean == b.mean && a.cov == b.cov; };
    if (pose.mean != o.pose.mean || pose.cov != o.pose.cov || ids != o.ids || map.size() != o.map.size()) return false;
    for (std::size_t i = 0; i < map.size(); ++i)
      if (!same(map[i], o.map[i]) || !same(landmarks[i], o.landmarks[i])) return false;
    return true;
  }
  typename Estimator::PoseEstimate pose;
  typename Estimator::MapEstimate map;
  std::vector<LandmarkId> ids;
  std::vector<typename Estimator::MapEstimate::value_type> landmarks;
};

template <class Config>
class ConcurrentReads : public ::testing::Test {};
using Configs = ::testing::Types<Ekf, Seif, Graph, Fast>;
TYPED_TEST_SUITE(ConcurrentReads, Configs);

TYPED_TEST(ConcurrentReads, ConstMethodsFromSeveralThreadsAtOnce) {
  // Two copies run the same steps: one is read from one thread, the other from four at once, so
  // that caches filled lazily by the first reader (SEIF's factor, GraphSLAM's marginals) are filled
  // concurrently in the second.
  const auto steps = test::random_linear_steps(15, 6, 11);
  auto reference = TypeParam::make();
  auto shared = TypeParam::make();
  eval::run(reference, steps);
  eval::run(shared, steps);
  const Reading expected(reference);
  constexpr int kThreads = 4, kRounds = 20;
  std::vector<int> mismatches(kThreads, 0);
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t)
    threads.emplace_back([&, t] {
      for (int r = 0; r < kRounds; ++r)
        if (!(Reading(shared) == expected)) ++mismatches[static_cast<std::size_t>(t)];
    });
  for (auto& thread : threads) thread.join();
  for (int t = 0; t < kThreads; ++t) EXPECT_EQ(mismatches[static_cast<std::size_t>(t)], 0) << "thread " << t;
}

TYPED_TEST(ConcurrentReads, IndependentEstimatorsInDifferentThreads) {
  const auto steps = test::random_linear_steps(15, 6, 12);
  auto reference = TypeParam::make();
  eval::run(reference, steps);
  const Reading expected(reference);
  constexpr int kThreads = 3;
  std::vector<int> same(kThreads, 0);
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t)
    threads.emplace_back([&, t] {
      auto own = TypeParam::make();
      eval::run(own, steps);
      same[static_cast<std::size_t>(t)] = Reading(own) == expected;
    });
  for (auto& thread : threads) thread.join();
  for (int t = 0; t < kThreads; ++t) EXPECT_TRUE(same[static_cast<std::size_t>(t)]) << "thread " << t;
}

}  // namespace
}  // namespace sextant
