// FastSLAM 2.0 time per step against map size with N = 100 particles, resampling at every step (the
// worst case for map copies): landmark maps shared in persistent trees (sextant's default) beside
// plain per-particle vectors. Both give the strong guarantee by working on a copy of the particles
// and committing at the end: O(N) with trees, but O(N J) with vectors, so the vector row is charged
// that rollback copy besides the O(N J) of every resample, as its name says. Heap per particle
// measured with glibc's mallinfo2 around the construction.
#include <benchmark/benchmark.h>

#include <cmath>
#include <numbers>
#include <sextant/sextant.hpp>

#include "sextant/testing/circle_world.hpp"

namespace {

using namespace sextant;
using testing::CircleWorld;
using testing::heap_in_use;
constexpr std::size_t kParticles = 100;

template <template <class> class Map>
void run(benchmark::State& state) {
  using Filter = FastSlam<BeaconShip2D, BeaconOffset2D, Map>;
  const CircleWorld world(static_cast<int>(state.range(0)));
  const std::size_t heap_before = heap_in_use();
  Filter fast{BeaconShip2D{0.05, 0.01, HeadingNoise::linearized}, BeaconOffset2D{0.1},
              {world.ship(0), 0.01 * Eigen::Matrix2d::Identity()},
              {.particles = kParticles, .version = FastSlamVersion::v2, .resample_threshold = 1.0}};
  fast.update(world.all_beacons());  // map every beacon first
  const double bytes = static_cast<double>(heap_in_use() - heap_before);
  int step = 0;
  for (auto _ : state) {
    ++step;
    fast.predict(world.control(step), 1.0);
    benchmark::DoNotOptimize(fast.update(world.observations(step)));
  }
  state.counters["landmarks"] = world.count;
  state.counters["bytes_per_particle_after_mapping"] = bytes / kParticles;
  // After many resamplings the particles share most of their maps.
  state.counters["bytes_per_particle_after_steps"] = static_cast<double>(heap_in_use() - heap_before) / kParticles;
  state.counters["resamplings"] = static_cast<double>(fast.resamplings());
}

void BM_FastSlamTreeMaps(benchmark::State& state) { run<PersistentArray>(state); }
void BM_FastSlamVectorMapsCopiedForRollbackAndResampling(benchmark::State& state) { run<CopiedArray>(state); }

void map_sizes(benchmark::internal::Benchmark* b) {
  for (int landmarks : {100, 1000, 10000}) b->Arg(landmarks);
  b->Unit(benchmark::kMicrosecond);
}

}  // namespace

BENCHMARK(BM_FastSlamTreeMaps)->Apply(map_sizes);
BENCHMARK(BM_FastSlamVectorMapsCopiedForRollbackAndResampling)->Apply(map_sizes);
BENCHMARK_MAIN();
