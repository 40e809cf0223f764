// The thesis's real-scale visual SLAM timing (seed 000, §5.4, Tables 15-17): the globe simulator at
// 120 steps with the landmark pool at Mmax = 10000 and max_new = 50, many features per frame (a dense
// globe, as KAZE on real images gives). Per back-end: the whole run's time split into motion
// (predict) and measurement (evictions + update, which for SEIF includes its mean recovery and
// sparsification); for GraphSLAM the time of one global update. And EKF's roofline: one update at the
// final map size against an Eigen matrix product of the covariance correction's shape (n x k times
// k x n), timed in the same run; GFLOP/s counters give the ratio.
#include <benchmark/benchmark.h>

#include <Eigen/Core>
#include <chrono>
#include <sextant/backends/ekf_slam.hpp>
#include <sextant/backends/graph_slam.hpp>
#include <sextant/backends/seif_slam.hpp>
#include <sextant/core/landmark_pool_policy.hpp>
#include <sextant/sim/globe_camera.hpp>

namespace {

using namespace sextant;
using Obs = Observation<Eigen::Vector3d>;
constexpr PoolLimits kPool{.max_landmarks = 10000, .max_new_per_step = 50};

const sim::GlobeCameraDataset& real_scale_globe() {
  static const auto data = sim::simulate_globe_camera(
      {.seed = 1, .num_steps = 120, .num_points = 20000, .max_features_per_frame = 200});
  return data;
}

/// Runs every step through the pool, timing predict and the rest apart.
template <class Backend>
void run_timed(Backend& backend, benchmark::State& state) {
  using Clock = std::chrono::steady_clock;
  const auto& data = real_scale_globe();
  LandmarkPoolPolicy policy(kPool);
  double motion = 0.0, measurement = 0.0;
  for (std::size_t k = 0; k < data.steps.size(); ++k) {
    const auto t0 = Clock::now();
    backend.predict(data.steps[k].control, data.steps[k].dt);
    const auto t1 = Clock::now();
    update_through_pool(backend, policy, std::span<const Obs>(data.steps[k].observations), k);
    const auto t2 = Clock::now();
    motion += std::chrono::duration<double>(t1 - t0).count();
    measurement += std::chrono::duration<double>(t2 - t1).count();
  }
  state.counters["motion_s"] = motion;
  state.counters["measurement_s"] = measurement;
  state.counters["landmarks"] = static_cast<double>(policy.size());
  state.counters["steps"] = static_cast<double>(data.steps.size());
}

void BM_GlobeEkf120Steps(benchmark::State& state) {
  const auto& data = real_scale_globe();
  for (auto _ : state) {
    EkfSlam<EulerCamera12D, PointInCamera3D> ekf(data.motion, data.sensor, data.prior);
    run_timed(ekf, state);
  }
}

void BM_GlobeSeif120Steps(benchmark::State& state) {
  const auto& data = real_scale_globe();
  for (auto _ : state) {
    SeifSlam<EulerCamera12D, PointInCamera3D> seif(data.motion, data.sensor, data.prior,
                                                   {.max_active = static_cast<std::size_t>(state.range(0))});
    run_timed(seif, state);
  }
  state.counters["active"] = static_cast<double>(state.range(0));
}

void BM_GlobeGraphOneGlobalUpdate(benchmark::State& state) {
  const auto& data = real_scale_globe();
  GraphSlam<EulerCamera12D, PointInCamera3D> graph(data.motion, data.sensor, data.prior, {.max_iterations = 1});
  LandmarkPoolPolicy policy(kPool);
  for (std::size_t k = 0; k < data.steps.size(); ++k) {
    graph.predict(data.steps[k].control, data.steps[k].dt);
    update_through_pool(graph, policy, std::span<const Obs>(data.steps[k].observations), k);
  }
  graph.optimize();  // the first update starts from dead reckoning; time the ones after it
  for (auto _ : state) benchmark::DoNotOptimize(graph.optimize());
  state.counters["landmarks"] = static_cast<double>(graph.num_landmarks());
}

/// EKF at the end of the run: the last step's observations (all known) as one update, against an
/// Eigen product of the covariance correction's shape, (n x k)(k x n), timed right after. Flops: the
/// correction updates the lower triangle of P by a rank-k product, n (n + 1) k; the product 2 n^2 k.
/// roofline = the EKF update's GFLOP/s over the product's (the update also forms K and S, so < 1).
void BM_GlobeEkfUpdateAtFinalSize(benchmark::State& state) {
  using Clock = std::chrono::steady_clock;
  const auto& data = real_scale_globe();
  EkfSlam<EulerCamera12D, PointInCamera3D> ekf(data.motion, data.sensor, data.prior);
  LandmarkPoolPolicy policy(kPool);
  for (std::size_t k = 0; k < data.steps.size(); ++k) {
    ekf.predict(data.steps[k].control, data.steps[k].dt);
    update_through_pool(ekf, policy, std::span<const Obs>(data.steps[k].observations), k);
  }
  std::vector<Obs> known;
  for (const auto& o : data.steps.back().observations)
    if (ekf.has_landmark(o.landmark_id)) known.push_back(o);
  const Eigen::Index n = ekf.state_dim(), rows = 3 * static_cast<Eigen::Index>(known.size());
  double best_update = 1e300;
  for (auto _ : state) {
    state.PauseTiming();
    auto copy = ekf;
    state.ResumeTiming();
    const auto start = Clock::now();
    benchmark::DoNotOptimize(copy.update(known));
    best_update = std::min(best_update, std::chrono::duration<double>(Clock::now() - start).count());
  }
  const Eigen::MatrixXd A = Eigen::MatrixXd::Random(n, rows), B = Eigen::MatrixXd::Random(rows, n);
  Eigen::MatrixXd C(n, n);
  double best_product = 1e300;
  for (int i = 0; i < 3; ++i) {
    const auto start = Clock::now();
    C.noalias() = A * B;
    benchmark::DoNotOptimize(C.data());
    best_product = std::min(best_product, std::chrono::duration<double>(Clock::now() - start).count());
  }
  const double dn = static_cast<double>(n), dk = static_cast<double>(rows);
  const double update_gflops = dn * (dn + 1) * dk * 1e-9 / best_update, product_gflops = 2 * dn * dn * dk * 1e-9 / best_product;
  state.counters["n"] = dn;
  state.counters["k"] = dk;
  state.counters["update_GFLOPs"] = update_gflops;
  state.counters["product_GFLOPs"] = product_gflops;
  state.counters["roofline"] = update_gflops / product_gflops;
}

}  // namespace

BENCHMARK(BM_GlobeEkf120Steps)->Iterations(1)->Unit(benchmark::kSecond);
BENCHMARK(BM_GlobeSeif120Steps)->Arg(150)->Arg(250)->Arg(0)->Iterations(1)->Unit(benchmark::kSecond);
BENCHMARK(BM_GlobeGraphOneGlobalUpdate)->Iterations(3)->Unit(benchmark::kSecond);
BENCHMARK(BM_GlobeEkfUpdateAtFinalSize)->Iterations(3)->Unit(benchmark::kMillisecond);
BENCHMARK_MAIN();
