// The thesis's real-scale visual SLAM timing (seed 000, §5.4, Tables 15-17): the globe simulator at
// 120 steps with the landmark pool at Mmax = 10000 and max_new = 50, on a dense globe whose detector
// responses change from frame to frame (as KAZE's do on real images), so that new landmarks keep
// entering the map as in the thesis's Figure 25. Per back-end: the run's time split into the
// thesis's stages (motion; measurement, which includes the pool's evictions; for SEIF also the update
// of the state estimate, i.e. mean recovery, and sparsification) and the thesis's Table 16 line
// fitted to the time per step over steps 20-60; for GraphSLAM the time of one global update. And
// EKF's roofline: one update at the final map size against an Eigen matrix product of the
// covariance correction's shape (n x k times k x n), timed in the same run.
#include <benchmark/benchmark.h>

#include <Eigen/Core>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <sextant/backends/ekf_slam.hpp>
#include <sextant/backends/graph_slam.hpp>
#include <sextant/backends/seif_slam.hpp>
#include <sextant/core/landmark_pool_policy.hpp>
#include <sextant/core/selected_inverse.hpp>
#include <sextant/sim/globe_camera.hpp>

namespace {

using namespace sextant;
using Obs = Observation<Eigen::Vector3d>;
using Clock = std::chrono::steady_clock;
using Ekf = EkfSlam<EulerCamera12D, PointInCamera3D>;
using Seif = SeifSlam<EulerCamera12D, PointInCamera3D>;
constexpr PoolLimits kPool{.max_landmarks = 10000, .max_new_per_step = 50};

/// 120 features per frame as in the globe run; a log-normal response jitter of 1 makes 50 new
/// landmarks a step until step ~25 and ~3,800 landmarks at step 120 (the thesis: 50 a step until
/// step ~65, Figure 25; its map size at 120 is not printed).
const sim::GlobeCameraDataset& real_scale_globe() {
  static const auto data = sim::simulate_globe_camera(
      {.seed = 1, .num_steps = 120, .num_points = 20000, .max_features_per_frame = 120, .response_jitter = 1.0});
  return data;
}

double seconds_since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

/// The thesis's Table 16 "fitted function": least-squares line a i + b through the time per step
/// over steps 20-60.
std::pair<double, double> fitted_line(const std::vector<double>& per_step) {
  double n = 0, si = 0, st = 0, sii = 0, sit = 0;
  for (std::size_t i = 20; i <= 60 && i < per_step.size(); ++i) {
    const double x = static_cast<double>(i), t = per_step[i];
    n += 1, si += x, st += t, sii += x * x, sit += x * t;
  }
  const double slope = (n * sit - si * st) / (n * sii - si * si);
  return {slope, (st - slope * si) / n};
}

/// The q-quantile of `values` (nearest rank).
double quantile(std::vector<double> values, double q) {
  const auto at = static_cast<std::size_t>(std::ceil(q * static_cast<double>(values.size()))) - 1;
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(at), values.end());
  return values[at];
}

/// Stage times summed over the run, and the time of each step.
struct StageTimes {
  double motion = 0, measurement = 0, mean_recovery = 0, sparsification = 0;
  std::vector<double> per_step;
};

template <class Backend>
void add_seif_stages(const Backend&, StageTimes&) {}
void add_seif_stages(const Seif& seif, StageTimes& times) {
  times.mean_recovery += seif.last_update_times().mean_recovery_s;
  times.sparsification += seif.last_update_times().sparsification_s;
}

/// Runs every step through the pool, timing the stages apart, and reports them as counters.
template <class Backend>
void run_timed(Backend& backend, benchmark::State& state) {
  const auto& data = real_scale_globe();
  LandmarkPoolPolicy policy(kPool);
  StageTimes times;
  for (std::size_t k = 0; k < data.steps.size(); ++k) {
    const auto t0 = Clock::now();
    backend.predict(data.steps[k].control, data.steps[k].dt);
    const double motion = seconds_since(t0);
    const auto t1 = Clock::now();
    update_through_pool(backend, policy, std::span<const Obs>(data.steps[k].observations), k);
    const double update = seconds_since(t1);
    times.motion += motion;
    times.measurement += update;
    add_seif_stages(backend, times);
    times.per_step.push_back(motion + update);
  }
  times.measurement -= times.mean_recovery + times.sparsification;
  const auto [slope, intercept] = fitted_line(times.per_step);
  state.counters["motion_s"] = times.motion;
  state.counters["measurement_s"] = times.measurement;
  state.counters["mean_recovery_s"] = times.mean_recovery;
  state.counters["sparsification_s"] = times.sparsification;
  state.counters["fit_slope_s"] = slope;
  state.counters["fit_intercept_s"] = intercept;
  state.counters["last_step_s"] = times.per_step.back();
  state.counters["median_step_s"] = quantile(times.per_step, 0.5);
  state.counters["p95_step_s"] = quantile(times.per_step, 0.95);
  state.counters["landmarks"] = static_cast<double>(policy.size());
  state.counters["steps"] = static_cast<double>(data.steps.size());
}

/// The EKF at the end of BM_GlobeEkf120Steps, for the roofline (running it again would double the
/// benchmark's time).
std::optional<Ekf>& final_ekf() {
  static std::optional<Ekf> ekf;
  return ekf;
}

void BM_GlobeEkf120Steps(benchmark::State& state) {
  const auto& data = real_scale_globe();
  for (auto _ : state) {
    Ekf ekf(data.motion, data.sensor, data.prior);
    run_timed(ekf, state);
    final_ekf() = std::move(ekf);
  }
}

/// SEIF with 150, 250 and 1000 active landmarks: the thesis's Table 15 calls the last "all active",
/// its Table 16 "SEIF 1000" (all of its simulated run's Mmax). With no limit at all the active block
/// holds the whole map (~3,800 landmarks here) and its mean recovery is a dense solve per step.
void BM_GlobeSeif120Steps(benchmark::State& state) {
  const auto& data = real_scale_globe();
  for (auto _ : state) {
    Seif seif(data.motion, data.sensor, data.prior,
                                                   {.max_active = static_cast<std::size_t>(state.range(0))});
    run_timed(seif, state);
  }
  state.counters["active"] = static_cast<double>(state.range(0));
}

/// SEIF with relocalization (ESEIF, the consistent sparsification; the camera's velocities relocalized
/// with the prior's covariance) and 150 or 250 active landmarks; `relocalizations` counts the steps
/// that relocalized.
void BM_GlobeRelocalizingSeif120Steps(benchmark::State& state) {
  const auto& data = real_scale_globe();
  for (auto _ : state) {
    Seif seif(data.motion, data.sensor, data.prior,
              {.max_active = static_cast<std::size_t>(state.range(0)), .sparsification = SeifSparsification::relocalization});
    run_timed(seif, state);
    state.counters["relocalizations"] = static_cast<double>(seif.relocalizations());
  }
  state.counters["active"] = static_cast<double>(state.range(0));
}

/// GraphSLAM online (GraphOptions::incremental): one Gauss-Newton step a frame on the incrementally
/// factorized reduced pose system. Counters as the filters' (median, 95th percentile, last step),
/// and global_update_s: one batch Gauss-Newton iteration over the same graph right after the run,
/// the work a batch GraphSLAM would do for a current estimate at that frame.
void BM_GlobeGraphOnline120Steps(benchmark::State& state) {
  const auto& data = real_scale_globe();
  for (auto _ : state) {
    GraphSlam<EulerCamera12D, PointInCamera3D> graph(data.motion, data.sensor, data.prior,
                                                     {.max_iterations = 1, .incremental = true});
    run_timed(graph, state);
    const auto start = Clock::now();
    graph.optimize();
    state.counters["global_update_s"] = seconds_since(start);
  }
}

/// GraphSLAM as a fixed-lag smoother (GraphOptions::lag = 10) on the same frames: at this scale ten
/// frames see ~1000 landmarks, so the window's dense system has ~3000 dimensions (docs/results/
/// real_time.md, "Fixed lag: memory kept between frames").
void BM_GlobeGraphFixedLag120Steps(benchmark::State& state) {
  const auto& data = real_scale_globe();
  for (auto _ : state) {
    GraphSlam<EulerCamera12D, PointInCamera3D> graph(data.motion, data.sensor, data.prior, {.lag = 10});
    run_timed(graph, state);
  }
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

/// GraphSLAM's marginals on the default globe (500 steps, 120 features a frame, Mmax = 1000) cut
/// after range(0) steps: the information matrix at the optimum, inverted by each method of
/// core/selected_inverse.hpp (range(1): 0 sparse Takahashi, 1 dense). Counters: the predicted work
/// of each (lookups sum_j c_j^2 and flops 2/3 n^3), whose time ratio calibrates the automatic choice.
void BM_GlobeGraphMarginals(benchmark::State& state) {
  const auto steps = static_cast<int>(state.range(0));
  const auto data = sim::simulate_globe_camera({.seed = 1, .num_steps = steps});
  GraphSlam<EulerCamera12D, PointInCamera3D> graph(data.motion, data.sensor, data.prior, {.window = 50});
  LandmarkPoolPolicy policy({.max_landmarks = 1000, .max_new_per_step = 50});
  for (std::size_t k = 0; k < data.steps.size(); ++k) {
    graph.predict(data.steps[k].control, data.steps[k].dt);
    update_through_pool(graph, policy, std::span<const Obs>(data.steps[k].observations), k);
  }
  graph.optimize();
  const Eigen::SparseMatrix<double> A = graph.information_matrix();
  const auto method = state.range(1) ? SelectedInverse::Method::dense : SelectedInverse::Method::sparse;
  for (auto _ : state) benchmark::DoNotOptimize(SelectedInverse(A, method).block(0, 12));
  double lookups = 0;
  for (Eigen::Index c : SelectedInverse::factor_column_counts(A)) lookups += static_cast<double>(c) * static_cast<double>(c);
  const double n = static_cast<double>(A.rows());
  state.counters["n"] = n;
  state.counters["lookups"] = lookups;
  state.counters["dense_flops"] = 2.0 / 3.0 * n * n * n;
  state.counters["automatic_is_dense"] = SelectedInverse::automatic_method(A) == SelectedInverse::Method::dense;
}

/// EKF at the end of the run: the last step's observations (all known) as one update, against an
/// Eigen product of the covariance correction's shape, (n x k)(k x n), timed right after. Flops: the
/// correction updates the lower triangle of P by a rank-k product, n (n + 1) k; the product 2 n^2 k.
/// roofline = the EKF update's GFLOP/s over the product's (the update also forms K and S, so < 1).
/// Runs right after BM_GlobeEkf120Steps and takes its final filter.
void BM_GlobeEkfUpdateAtFinalSize(benchmark::State& state) {
  const auto& data = real_scale_globe();
  if (!final_ekf()) {
    state.SkipWithError("BM_GlobeEkf120Steps did not run first (filter with --benchmark_filter=GlobeEkf)");
    return;
  }
  const Ekf& ekf = *final_ekf();
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
    best_update = std::min(best_update, seconds_since(start));
  }
  const Eigen::MatrixXd A = Eigen::MatrixXd::Random(n, rows), B = Eigen::MatrixXd::Random(rows, n);
  Eigen::MatrixXd C(n, n);
  double best_product = 1e300;
  for (int i = 0; i < 3; ++i) {
    const auto start = Clock::now();
    C.noalias() = A * B;
    benchmark::DoNotOptimize(C.data());
    best_product = std::min(best_product, seconds_since(start));
  }
  const double dn = static_cast<double>(n), dk = static_cast<double>(rows);
  const double update_gflops = dn * (dn + 1) * dk * 1e-9 / best_update, product_gflops = 2 * dn * dn * dk * 1e-9 / best_product;
  state.counters["n"] = dn;
  state.counters["k"] = dk;
  state.counters["update_GFLOPs"] = update_gflops;
  state.counters["product_GFLOPs"] = product_gflops;
  state.counters["roofline"] = update_gflops / product_gflops;
  final_ekf().reset();  // 1 GB of covariance the other benchmarks do not need
}

}  // namespace

BENCHMARK(BM_GlobeEkf120Steps)->Iterations(1)->Unit(benchmark::kSecond);
BENCHMARK(BM_GlobeEkfUpdateAtFinalSize)->Iterations(3)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_GlobeSeif120Steps)->Arg(150)->Arg(250)->Arg(1000)->Iterations(1)->Unit(benchmark::kSecond);
BENCHMARK(BM_GlobeRelocalizingSeif120Steps)->Arg(150)->Arg(250)->Iterations(1)->Unit(benchmark::kSecond);
BENCHMARK(BM_GlobeGraphOnline120Steps)->Iterations(1)->Unit(benchmark::kSecond);
BENCHMARK(BM_GlobeGraphFixedLag120Steps)->Iterations(1)->Unit(benchmark::kSecond);
BENCHMARK(BM_GlobeGraphOneGlobalUpdate)->Iterations(3)->Unit(benchmark::kSecond);
BENCHMARK(BM_GlobeGraphMarginals)
    ->ArgsProduct({{30, 60, 100}, {0, 1}})
    ->Args({500, 1})
    ->Iterations(1)
    ->Unit(benchmark::kSecond);
BENCHMARK_MAIN();
