// SEIF-SLAM time per step against map size with max_active fixed (the thesis's sparsification and
// relocalization, ESEIF), beside EKF-SLAM, in one run; and the
// heap memory each holds per landmark (measured with glibc's mallinfo2 around the construction).
// The ship drives around a circle of beacons, seeing the 4 nearest at every step. The *WithPose rows
// add the pose() (mean and marginal covariance) an evaluation reads after every step: O(1) for the
// EKF, a sparse Cholesky factorization of Omega for SEIF.
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdint>
#include <numbers>
#include <sextant/sextant.hpp>

#include "sextant/testing/circle_world.hpp"

namespace {

using namespace sextant;
using testing::CircleWorld;
using testing::heap_in_use;
using Seif = SeifSlam<BeaconShip2D, BeaconOffset2D>;
using Ekf = EkfSlam<BeaconShip2D, BeaconOffset2D>;
constexpr std::size_t kMaxActive = 8;

const BeaconShip2D kMotion{0.05, 0.01, HeadingNoise::linearized};
const BeaconOffset2D kSensor{0.1};
Gaussian<Eigen::Vector2d, 2> prior(const CircleWorld& world) { return {world.ship(0), 0.01 * Eigen::Matrix2d::Identity()}; }

/// SEIF after one lap: every beacon mapped, the way a filter builds its map.
template <SeifSparsification kSparsification = SeifSparsification::thesis>
Seif seif_after_one_lap(const CircleWorld& world) {
  Seif seif{kMotion, kSensor, prior(world), {.max_active = kMaxActive, .sparsification = kSparsification}};
  seif.update(world.observations(0));
  for (int step = 1; step <= world.count; ++step) {
    seif.predict(world.control(step), 1.0);
    seif.update(world.observations(step));
  }
  return seif;
}

/// EKF with every beacon mapped (built in one update: a lap would take hours at 10,000 beacons).
Ekf ekf_with_map(const CircleWorld& world) {
  Ekf ekf{kMotion, kSensor, prior(world)};
  ekf.update(world.all_beacons());
  return ekf;
}

template <class Backend, bool kReadPose, class Build>
void run_steps(benchmark::State& state, Build build) {
  const CircleWorld world(static_cast<int>(state.range(0)));
  const std::size_t heap_before = heap_in_use();
  Backend backend = build(world);
  const double bytes = static_cast<double>(heap_in_use() - heap_before);
  int step = world.count;
  std::uint64_t relocalizations_before = 0;
  if constexpr (requires { backend.relocalizations(); }) relocalizations_before = backend.relocalizations();
  for (auto _ : state) {
    ++step;
    backend.predict(world.control(step), 1.0);
    benchmark::DoNotOptimize(backend.update(world.observations(step)));
    if constexpr (kReadPose) benchmark::DoNotOptimize(backend.pose());
  }
  if constexpr (requires { backend.relocalizations(); })  // ESEIF: the share of steps that relocalized
    state.counters["relocalized"] = static_cast<double>(backend.relocalizations() - relocalizations_before) /
                                    static_cast<double>(step - world.count);
  state.counters["landmarks"] = world.count;
  state.counters["bytes_per_landmark"] = bytes / world.count;
}

void BM_SeifStep(benchmark::State& state) { run_steps<Seif, false>(state, seif_after_one_lap<>); }
void BM_EseifStep(benchmark::State& state) {
  run_steps<Seif, false>(state, seif_after_one_lap<SeifSparsification::relocalization>);
}
void BM_EkfStep(benchmark::State& state) { run_steps<Ekf, false>(state, ekf_with_map); }
void BM_SeifStepWithPose(benchmark::State& state) { run_steps<Seif, true>(state, seif_after_one_lap<>); }
void BM_EkfStepWithPose(benchmark::State& state) { run_steps<Ekf, true>(state, ekf_with_map); }

void map_sizes(benchmark::internal::Benchmark* b) {
  for (int landmarks : {100, 300, 1000, 3000, 10000}) b->Arg(landmarks);
  b->Unit(benchmark::kMicrosecond);
}

}  // namespace

BENCHMARK(BM_SeifStep)->Apply(map_sizes);
BENCHMARK(BM_EseifStep)->Apply(map_sizes);
BENCHMARK(BM_EkfStep)->Apply(map_sizes);
BENCHMARK(BM_SeifStepWithPose)->Apply(map_sizes);
BENCHMARK(BM_EkfStepWithPose)->Apply(map_sizes);
BENCHMARK_MAIN();
