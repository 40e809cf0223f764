#include "sextant/core/landmark_pool_policy.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <set>

#include "sextant/backends/ekf_slam.hpp"
#include "sextant/backends/seif_slam.hpp"
#include "sextant/models/beacon_ship_2d.hpp"
#include "sextant/sim/ship_2d.hpp"

namespace sextant {
namespace {

using Obs = Observation<Eigen::Vector2d>;

std::vector<Obs> observe(std::initializer_list<LandmarkId> ids) {
  std::vector<Obs> out;
  for (LandmarkId id : ids) out.push_back({id, Eigen::Vector2d::Zero()});
  return out;
}

std::vector<LandmarkId> ids_of(const std::vector<Obs>& observations) {
  std::vector<LandmarkId> out;
  for (const auto& o : observations) out.push_back(o.landmark_id);
  return out;
}

TEST(LandmarkPoolPolicy, EvictsTheLeastRecentlySeenSmallerIdFirstAndNeverOneSeenNow) {
  LandmarkPoolPolicy policy({.max_landmarks = 4, .max_new_per_step = 4});
  auto commit = [&](std::vector<Obs> observations, std::size_t step) {
    const auto plan = policy.plan(std::span<const Obs>(observations));
    policy.commit(plan, step);
    return plan;
  };
  commit(observe({10, 11}), 0);
  commit(observe({12, 13}), 1);
  // Full. 11 and 10 are the oldest (step 0; 10 < 11); 10 is seen now, so 11 and then 12 go.
  const auto plan = commit(observe({10, 20, 21}), 2);
  EXPECT_EQ(plan.evict, (std::vector<LandmarkId>{11, 12}));
  EXPECT_EQ(ids_of(plan.observations), (std::vector<LandmarkId>{10, 20, 21}));
  EXPECT_EQ(policy.size(), 4u);
  EXPECT_TRUE(policy.contains(13) && policy.contains(10) && !policy.contains(11));
  // Every landmark in the pool is observed: nothing can be evicted, so no new one is admitted.
  const auto full = commit(observe({10, 13, 20, 21, 30}), 3);
  EXPECT_TRUE(full.evict.empty());
  EXPECT_EQ(full.added, 0u);
  EXPECT_EQ(full.refused, 1u);
  EXPECT_EQ(policy.history().back().in_pool, 4u);
}

TEST(LandmarkPoolPolicy, FewestSightingsEvictsTheLandmarkSeenInTheFewestStepsFirst) {
  LandmarkPoolPolicy policy({.max_landmarks = 4, .max_new_per_step = 4, .eviction = PoolEviction::fewest_sightings});
  auto commit = [&](std::vector<Obs> observations, std::size_t step) {
    const auto plan = policy.plan(std::span<const Obs>(observations));
    policy.commit(plan, step);
    return plan;
  };
  commit(observe({10, 11}), 0);
  commit(observe({10}), 1);
  commit(observe({10}), 2);
  commit(observe({12, 13}), 3);
  // 10 seen at three steps, 11, 12 and 13 at one; the least recently seen first among equals (11),
  // then the smaller id (12). The thesis's order would have taken 11 and 10.
  const auto plan = commit(observe({14, 15}), 4);
  EXPECT_EQ(plan.evict, (std::vector<LandmarkId>{11, 12}));
  EXPECT_TRUE(policy.contains(10) && policy.contains(13) && policy.contains(14) && policy.contains(15));
  // A landmark seen twice in one step counts one step: 13 and 14 (one step each, 13 the older)
  // against 15 (steps 4 and 5) and 10 (three steps).
  commit(observe({15}), 5);
  commit(observe({15}), 5);
  EXPECT_EQ(commit(observe({20}), 6).evict, (std::vector<LandmarkId>{13}));
  EXPECT_EQ(commit(observe({21}), 7).evict, (std::vector<LandmarkId>{14}));
  EXPECT_EQ(commit(observe({22}), 8).evict, (std::vector<LandmarkId>{20}));
  EXPECT_TRUE(policy.contains(10) && policy.contains(15));
}

/// A back-end that only says which removals would add links (as SeifSlam::removal_adds_no_links).
struct BackendWithFill {
  std::set<LandmarkId> with_fill, removed;
  bool removal_adds_no_links(LandmarkId id) const { return !with_fill.contains(id); }
  void remove_landmark(LandmarkId id) { removed.insert(id); }
  UpdateResult update(std::span<const Obs>) { return {}; }
};

TEST(LandmarkPoolPolicy, FewestSightingsWithoutFillPassesOverARemovalThatWouldAddLinks) {
  const PoolLimits limits{.max_landmarks = 4, .max_new_per_step = 4, .eviction = PoolEviction::fewest_sightings_without_fill};
  LandmarkPoolPolicy policy(limits);
  BackendWithFill backend{.with_fill = {10, 11}};
  auto step = [&](std::initializer_list<LandmarkId> ids, std::size_t k) {
    backend.removed.clear();
    const auto observations = observe(ids);
    update_through_pool(backend, policy, std::span<const Obs>(observations), k);
    return backend.removed;
  };
  step({10}, 0);
  step({10}, 1);
  step({11}, 2);
  step({12, 13}, 3);
  // Fewest sightings: 11, 12, 13 (one step each), then 10 (two). 10 and 11 would add links, so 12
  // and 13 go (fewest_sightings would take 11 and 12, the thesis's order 10 and 11).
  EXPECT_EQ(step({14, 15}, 4), (std::set<LandmarkId>{12, 13}));
  // Only 10 and 11 (both with fill) are left besides the landmarks seen now: the least recently
  // seen goes, 10 (last seen at step 1), not 11, which fewest_sightings would take.
  EXPECT_EQ(step({14, 15, 16}, 5), (std::set<LandmarkId>{10}));
  EXPECT_EQ(step({20}, 6), (std::set<LandmarkId>{16}));  // 11 still passed over
  // A plan without the back-end's answer treats every removal as adding none.
  const auto observations = observe({21});
  EXPECT_EQ(policy.plan(std::span<const Obs>(observations)).evict, (std::vector<LandmarkId>{11}));
}

TEST(LandmarkPoolPolicy, AdmitsNewLandmarksInTheGivenOrderUpToThePerStepLimit) {
  LandmarkPoolPolicy policy({.max_landmarks = 100, .max_new_per_step = 2});
  const auto observations = observe({5, 3, 9, 1});
  const auto plan = policy.plan(std::span<const Obs>(observations));
  EXPECT_EQ(ids_of(plan.observations), (std::vector<LandmarkId>{5, 3}));
  EXPECT_EQ(plan.added, 2u);
  EXPECT_EQ(plan.refused, 2u);
  EXPECT_EQ(policy.size(), 0u) << "plan() must not change the policy";
}

TEST(LandmarkPoolPolicy, RejectsARepeatedIdAndAnEmptyPool) {
  LandmarkPoolPolicy policy({.max_landmarks = 3, .max_new_per_step = 3});
  const auto observations = observe({1, 2, 1});
  EXPECT_THROW(policy.plan(std::span<const Obs>(observations)), duplicate_landmark_error);
  EXPECT_THROW(LandmarkPoolPolicy({.max_landmarks = 0, .max_new_per_step = 1}), invalid_input_error);
}

TEST(LandmarkPoolPolicy, NeverExceedsCapacityOrThePerStepLimitOnARandomStream) {
  std::mt19937_64 rng(3);
  std::uniform_int_distribution<LandmarkId> id(0, 300);
  std::uniform_int_distribution<int> count(0, 40);
  for (const PoolEviction eviction :
       {PoolEviction::least_recently_seen, PoolEviction::fewest_sightings, PoolEviction::fewest_sightings_without_fill}) {
    const PoolLimits limits{.max_landmarks = 60, .max_new_per_step = 7, .eviction = eviction};
    LandmarkPoolPolicy policy(limits);
    std::set<LandmarkId> pool;
    for (std::size_t step = 0; step < 2000; ++step) {
      std::set<LandmarkId> ids;
      const int n = count(rng);
      while (static_cast<int>(ids.size()) < n) ids.insert(id(rng));
      std::vector<Obs> observations;
      for (LandmarkId i : ids) observations.push_back({i, Eigen::Vector2d::Zero()});
      std::shuffle(observations.begin(), observations.end(), rng);
      const auto plan = policy.plan(std::span<const Obs>(observations));
      for (LandmarkId e : plan.evict) {
        ASSERT_EQ(pool.erase(e), 1u) << "evicted a landmark not in the pool";
        ASSERT_FALSE(ids.contains(e)) << "evicted a landmark observed in this step";
      }
      std::size_t added = 0;
      for (const auto& o : plan.observations) added += pool.insert(o.landmark_id).second;
      ASSERT_EQ(added, plan.added);
      ASSERT_LE(added, limits.max_new_per_step);
      ASSERT_LE(pool.size(), limits.max_landmarks);
      policy.commit(plan, step);
      ASSERT_EQ(policy.size(), pool.size());
      ASSERT_EQ(policy.history().back().in_pool, pool.size());
    }
  }
}

/// A filter run through the pool against the same filter keeping every landmark, on the ship
/// (linear models). The stream leaves out re-observations of evicted landmarks (which the pool
/// would start anew), so the pooled filter must hold exactly the marginal of the full filter.
template <class Pooled, class Full>
void expect_pool_equals_marginal_of_full_filter(Pooled& pooled, Full& full, const sim::Ship2DDataset& data) {
  LandmarkPoolPolicy policy({.max_landmarks = 12, .max_new_per_step = 3});
  std::set<LandmarkId> evicted;
  std::size_t evictions = 0;
  double worst = 0.0;
  for (std::size_t k = 0; k < data.steps.size(); ++k) {
    const auto& step = data.steps[k];
    std::vector<Obs> observations;
    for (const auto& o : step.observations)
      if (!evicted.contains(o.landmark_id)) observations.push_back(o);
    pooled.predict(step.control, step.dt);
    full.predict(step.control, step.dt);
    const auto plan = policy.plan(std::span<const Obs>(observations));
    for (LandmarkId id : plan.evict) {
      pooled.remove_landmark(id);
      evicted.insert(id);
      ++evictions;
    }
    pooled.update(plan.observations);
    full.update(plan.observations);
    policy.commit(plan, k);
    if (k % 50 != 0 && k + 1 != data.steps.size()) continue;
    const auto a = pooled.pose(), b = full.pose();
    const double scale = std::max(1.0, b.mean.cwiseAbs().maxCoeff());
    worst = std::max({worst, (a.mean - b.mean).cwiseAbs().maxCoeff() / scale,
                      (a.cov - b.cov).cwiseAbs().maxCoeff() / b.cov.cwiseAbs().maxCoeff()});
    for (const auto& landmark : pooled.map()) {
      const auto other = full.landmark(landmark.id);
      worst = std::max({worst, (landmark.mean - other.mean).cwiseAbs().maxCoeff() / scale,
                        (landmark.cov - other.cov).cwiseAbs().maxCoeff() / other.cov.cwiseAbs().maxCoeff()});
    }
  }
  EXPECT_GT(evictions, 20u) << "the run must exercise eviction";
  EXPECT_LT(worst, 1e-9);
}

TEST(LandmarkPoolPolicy, EkfAfterEvictionsHoldsTheMarginalOfTheFullEkf) {
  const auto data = sim::simulate_ship_2d({.seed = 2, .num_steps = 600});
  EkfSlam<BeaconShip2D, BeaconOffset2D> pooled(data.motion, data.sensor, data.prior), full(data.motion, data.sensor, data.prior);
  expect_pool_equals_marginal_of_full_filter(pooled, full, data);
}

TEST(LandmarkPoolPolicy, SeifWithoutSparsificationAfterEvictionsHoldsTheMarginalOfTheFullEkf) {
  const auto data = sim::simulate_ship_2d({.seed = 2, .num_steps = 600});
  SeifSlam<BeaconShip2D, BeaconOffset2D> pooled(data.motion, data.sensor, data.prior,
                                                {.max_active = 0, .exact_recovery_period = 1});
  EkfSlam<BeaconShip2D, BeaconOffset2D> full(data.motion, data.sensor, data.prior);
  expect_pool_equals_marginal_of_full_filter(pooled, full, data);
}

}  // namespace
}  // namespace sextant
