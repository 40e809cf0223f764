// EKF-SLAM time per step against map size: sextant's block-sparse step (predict + update of k known
// landmarks, and the pose() an evaluation reads after it) beside the thesis's own update with a dense
// full H and P = P - K S K^T (eqs. 14-17, O(n^2 k)) on the same filter state. Run with --benchmark_format=json and benchmarks/ratio_table.py for the
// ratio table in docs/benchmarks.md.
#include <benchmark/benchmark.h>

#include <sextant/sextant.hpp>
#include <sextant/testing/textbook_ekf.hpp>

namespace {

using namespace sextant;
using Ekf = EkfSlam<BeaconShip2D, BeaconOffset2D>;
using Obs = Observation<Eigen::Vector2d>;
constexpr int kObservationsPerStep = 4;

/// A filter that already holds `landmarks` beacons on a grid around the ship.
Ekf filter_with_map(int landmarks) {
  Ekf ekf{BeaconShip2D{}, BeaconOffset2D{}, {Eigen::Vector2d::Zero(), Eigen::Matrix2d::Identity()}};
  std::vector<Obs> all;
  for (int j = 0; j < landmarks; ++j) all.push_back({static_cast<LandmarkId>(j), Eigen::Vector2d(j % 100, j / 100)});
  ekf.update(all);
  return ekf;
}

/// The k observations of step `step`: a sliding window over the map.
std::vector<Obs> observations_at(int step, int landmarks) {
  std::vector<Obs> out;
  for (int i = 0; i < kObservationsPerStep; ++i) {
    const int j = (step * kObservationsPerStep + i) % landmarks;
    out.push_back({static_cast<LandmarkId>(j), Eigen::Vector2d(j % 100, j / 100)});
  }
  return out;
}

void BM_EkfStepBlockSparse(benchmark::State& state) {
  const int landmarks = static_cast<int>(state.range(0));
  Ekf ekf = filter_with_map(landmarks);
  int step = 0;
  for (auto _ : state) {
    ekf.predict(Eigen::Vector2d(0.0, 0.0), 1.0);
    benchmark::DoNotOptimize(ekf.update(observations_at(step++, landmarks)));
    benchmark::DoNotOptimize(ekf.pose());
  }
  state.counters["landmarks"] = landmarks;
  state.counters["state_dim"] = static_cast<double>(ekf.state_dim());
}

void BM_EkfUpdateDenseTextbook(benchmark::State& state) {
  const int landmarks = static_cast<int>(state.range(0));
  const Ekf ekf = filter_with_map(landmarks);
  const auto dense = testing::linearize_dense(ekf, BeaconOffset2D{}, observations_at(0, landmarks));
  Eigen::MatrixXd P = ekf.covariance();
  Eigen::VectorXd mean = Eigen::VectorXd::Zero(P.rows());
  for (auto _ : state) {
    testing::textbook_ekf_update(P, mean, dense.H, dense.Q, dense.residual);
    benchmark::DoNotOptimize(P.data());
    benchmark::ClobberMemory();
  }
  state.counters["landmarks"] = landmarks;
  state.counters["state_dim"] = static_cast<double>(P.rows());
}

}  // namespace

void map_sizes(benchmark::internal::Benchmark* b) {
  for (int landmarks : {50, 100, 200, 400, 800, 1600, 3200}) b->Arg(landmarks);
  b->Unit(benchmark::kMicrosecond);
}
BENCHMARK(BM_EkfStepBlockSparse)->Apply(map_sizes);
BENCHMARK(BM_EkfUpdateDenseTextbook)->Apply(map_sizes);
BENCHMARK_MAIN();
