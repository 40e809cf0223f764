// SEIF-SLAM time per step against map size with max_active fixed, beside EKF-SLAM, in one run; and the
// heap memory each holds per landmark (measured with glibc's mallinfo2 around the construction).
// The ship drives around a circle of beacons, seeing the 4 nearest at every step.
#include <benchmark/benchmark.h>
#include <malloc.h>

#include <cmath>
#include <numbers>
#include <sextant/sextant.hpp>

namespace {

using namespace sextant;
using Seif = SeifSlam<BeaconShip2D, BeaconOffset2D>;
using Ekf = EkfSlam<BeaconShip2D, BeaconOffset2D>;
using Obs = Observation<Eigen::Vector2d>;
constexpr int kObservationsPerStep = 4;
constexpr std::size_t kMaxActive = 8;

/// Beacons on a circle, one unit apart; the ship sails a circle 3 units inside, one beacon per step.
struct CircleWorld {
  explicit CircleWorld(int landmarks) : count(landmarks), radius(landmarks / (2.0 * std::numbers::pi)) {}
  double angle(int j) const { return 2.0 * std::numbers::pi * (j % count) / count; }
  Eigen::Vector2d beacon(int j) const { return radius * Eigen::Vector2d(std::cos(angle(j)), std::sin(angle(j))); }
  Eigen::Vector2d ship(int step) const { return (radius - 3.0) * Eigen::Vector2d(std::cos(angle(step)), std::sin(angle(step))); }
  Eigen::Vector2d control(int step) const {  // (speed, heading) from ship(step - 1) to ship(step)
    const Eigen::Vector2d d = ship(step) - ship(step - 1);
    return {d.norm(), std::atan2(d.y(), d.x())};
  }
  std::vector<Obs> observations(int step) const {
    std::vector<Obs> out;
    for (int i = 0; i < kObservationsPerStep; ++i) {
      const int j = (step + i) % count;
      out.push_back({static_cast<LandmarkId>(j), beacon(j) - ship(step)});
    }
    return out;
  }
  int count;
  double radius;
};

const BeaconShip2D kMotion{0.05, 0.01, HeadingNoise::linearized};
const BeaconOffset2D kSensor{0.1};
Gaussian<Eigen::Vector2d, 2> prior(const CircleWorld& world) { return {world.ship(0), 0.01 * Eigen::Matrix2d::Identity()}; }

/// Heap bytes in use: small blocks plus the mmapped large ones (a big covariance lives there).
std::size_t heap_in_use() {
  const auto info = mallinfo2();
  return info.uordblks + info.hblkhd;
}

/// SEIF after one lap: every beacon mapped, the way a filter builds its map.
Seif seif_after_one_lap(const CircleWorld& world) {
  Seif seif{kMotion, kSensor, prior(world), {.max_active = kMaxActive}};
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
  std::vector<Obs> all;
  for (int j = 0; j < world.count; ++j) all.push_back({static_cast<LandmarkId>(j), world.beacon(j) - world.ship(0)});
  ekf.update(all);
  return ekf;
}

template <class Backend, class Build>
void run_steps(benchmark::State& state, Build build) {
  const CircleWorld world(static_cast<int>(state.range(0)));
  const std::size_t heap_before = heap_in_use();
  Backend backend = build(world);
  const double bytes = static_cast<double>(heap_in_use() - heap_before);
  int step = world.count;
  for (auto _ : state) {
    ++step;
    backend.predict(world.control(step), 1.0);
    benchmark::DoNotOptimize(backend.update(world.observations(step)));
  }
  state.counters["landmarks"] = world.count;
  state.counters["bytes_per_landmark"] = bytes / world.count;
}

void BM_SeifStep(benchmark::State& state) { run_steps<Seif>(state, seif_after_one_lap); }
void BM_EkfStep(benchmark::State& state) { run_steps<Ekf>(state, ekf_with_map); }

void map_sizes(benchmark::internal::Benchmark* b) {
  for (int landmarks : {100, 300, 1000, 3000, 10000}) b->Arg(landmarks);
  b->Unit(benchmark::kMicrosecond);
}

}  // namespace

BENCHMARK(BM_SeifStep)->Apply(map_sizes);
BENCHMARK(BM_EkfStep)->Apply(map_sizes);
BENCHMARK_MAIN();
