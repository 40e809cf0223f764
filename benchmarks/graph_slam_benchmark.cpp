// GraphSLAM's optimize() beside Ceres on the same problems from the same starting point: the
// 1390-step ship and cityTrees10000 (../shared/data). Each runs as its users run it: GraphSLAM with
// its default options, Ceres with its default Solver::Options (LM, its own stopping tolerances)
// except the linear solver (SPARSE_SCHUR or SPARSE_NORMAL_CHOLESKY) on SuiteSparse, one thread.
// Counters: chi2 (final), iterations, and to_optimum_ms, the time at which the solver's own log
// first shows a chi2 within 1e-6 (relative) of the optimum (computed once per problem by
// running Ceres to the stationary point), -1 if it stops before.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <sextant/sextant.hpp>

#include "support/ceres_problems.hpp"

namespace {

using namespace sextant;
using ShipGraph = GraphSlam<BeaconShip2D, BeaconOffset2D>;
using PlanarGraph = GraphSlam<Se2Odometry, PointInRobotFrame2D>;

const std::string kCityTrees = std::string(SEXTANT_SHARED_DATA_DIR) + "/city_trees/cityTrees10000.txt";
const Eigen::Matrix3d kFirstPoseCov = 1e-6 * Eigen::Matrix3d::Identity();

const sim::Ship2DDataset& ship() {
  static const auto data = sim::simulate_ship_2d({.seed = 1});
  return data;
}
const io::PlanarDataset* city_trees() {
  static const auto data = std::filesystem::exists(kCityTrees)
                               ? std::optional(io::read_isam_2d(kCityTrees, io::IsamNoise::square_root_information))
                               : std::nullopt;
  return data ? &*data : nullptr;
}

ShipGraph ship_graph(GraphOptions options) {
  ShipGraph graph{ship().motion, ship().sensor, ship().prior, options};
  eval::run(graph, ship().steps);
  return graph;
}
PlanarGraph planar_graph(const io::PlanarDataset& data, GraphOptions options) {
  PointInRobotFrame2D sensor;
  sensor.Q = data.landmark_cov;
  PlanarGraph graph{Se2Odometry{}, sensor, {Eigen::Vector3d::Zero(), kFirstPoseCov}, options};
  graph.update(data.initial_observations);
  for (const auto& step : data.steps) {
    graph.predict(step.control, step.dt);
    graph.update(step.observations);
  }
  return graph;
}

/// The first time at which chi2 (given per iteration with its time) is within 1e-6 of the optimum.
double time_to_optimum_ms(const std::vector<double>& chi2, const std::vector<double>& seconds, double optimum) {
  for (std::size_t i = 0; i < chi2.size(); ++i)
    if (chi2[i] <= optimum * (1.0 + 1e-6)) return 1e3 * seconds[i];
  return -1.0;
}

template <int X, class Build>
double optimum_by_ceres(Build build) {
  test::CeresGraph<X> peer;
  build(peer);
  return 2.0 * peer.solve(ceres::SPARSE_NORMAL_CHOLESKY, test::CeresStopping::optimum).final_cost;
}

template <class Graph, class Make>
void optimize_graph(benchmark::State& state, Make make, double optimum) {
  double cost = 0.0, to_optimum = -1.0;
  int iterations = 0;
  for (auto _ : state) {
    state.PauseTiming();
    Graph graph = make();
    state.ResumeTiming();
    const auto summary = graph.optimize();
    state.PauseTiming();
    cost = summary.cost.back();
    iterations = summary.iterations;
    to_optimum = time_to_optimum_ms(summary.cost, summary.seconds, optimum);
    state.ResumeTiming();
  }
  state.counters["chi2"] = cost;
  state.counters["iterations"] = iterations;
  state.counters["to_optimum_ms"] = to_optimum;
}

template <int X, class Build>
void solve_with_ceres(benchmark::State& state, ceres::LinearSolverType type, Build build, double optimum) {
  double cost = 0.0, to_optimum = -1.0;
  int iterations = 0;
  for (auto _ : state) {
    state.PauseTiming();
    auto peer = std::make_unique<test::CeresGraph<X>>();
    build(*peer);
    state.ResumeTiming();
    const auto summary = peer->solve(type, test::CeresStopping::defaults);
    state.PauseTiming();
    cost = 2.0 * summary.final_cost;  // Ceres reports chi2 / 2
    iterations = static_cast<int>(summary.iterations.size()) - 1;  // entry 0 is the start
    std::vector<double> chi2, seconds;
    for (const auto& it : summary.iterations) {
      chi2.push_back(2.0 * it.cost);
      seconds.push_back(it.cumulative_time_in_seconds);
    }
    to_optimum = time_to_optimum_ms(chi2, seconds, optimum);
    peer.reset();
    state.ResumeTiming();
  }
  state.counters["chi2"] = cost;
  state.counters["iterations"] = iterations;
  state.counters["to_optimum_ms"] = to_optimum;
}

// Ceres starts where GraphSLAM starts: dead reckoning and the inverse measurement model.
void build_ship_peer(test::CeresGraph<2>& peer) {
  const ShipGraph start = ship_graph({});
  for (const auto& pose : start.pose_means()) peer.poses.push_back(pose);
  for (const auto& landmark : start.map()) peer.landmarks[landmark.id] = landmark.mean;
  std::vector<Eigen::Matrix2d> cov;
  std::vector<Eigen::Vector2d> displacement;
  for (const auto& step : ship().steps) {
    const auto p = ship().motion.predict(Eigen::Vector2d::Zero(), step.control, step.dt);
    cov.push_back(p.R);
    displacement.push_back(p.x);
  }
  test::build_ship(peer, ship().prior.mean, ship().prior.cov, ship().steps, cov, displacement, ship().sensor.noise());
}
void build_city_trees_peer(test::CeresGraph<3>& peer) {
  const auto& data = *city_trees();
  const PlanarGraph start = planar_graph(data, {});
  for (const auto& pose : start.pose_means()) peer.poses.push_back(pose);
  for (LandmarkId id : start.landmark_ids()) peer.landmarks[id] = start.landmark(id).mean;
  test::build_planar(peer, kFirstPoseCov, data.initial_observations, data.steps, data.landmark_cov);
}

double ship_optimum() {
  static const double optimum = optimum_by_ceres<2>(build_ship_peer);
  return optimum;
}
double city_trees_optimum() {
  static const double optimum = optimum_by_ceres<3>(build_city_trees_peer);
  return optimum;
}

// The ship.
void BM_Ship_GraphSlam(benchmark::State& state) {
  optimize_graph<ShipGraph>(state, [] { return ship_graph({}); }, ship_optimum());
}
void BM_Ship_GraphSlamLandmarkSchur(benchmark::State& state) {
  optimize_graph<ShipGraph>(state, [] { return ship_graph({.solver = GraphSolver::landmark_schur}); }, ship_optimum());
}
void BM_Ship_CeresSparseSchur(benchmark::State& state) {
  solve_with_ceres<2>(state, ceres::SPARSE_SCHUR, build_ship_peer, ship_optimum());
}
void BM_Ship_CeresSparseNormalCholesky(benchmark::State& state) {
  solve_with_ceres<2>(state, ceres::SPARSE_NORMAL_CHOLESKY, build_ship_peer, ship_optimum());
}

// cityTrees10000.
bool require_city_trees(benchmark::State& state) {
  if (city_trees()) return true;
  state.SkipWithError(("data set not found: " + kCityTrees).c_str());
  for (auto _ : state) {
  }
  return false;
}
void BM_CityTrees_GraphSlam(benchmark::State& state) {
  if (require_city_trees(state))
    optimize_graph<PlanarGraph>(state, [] { return planar_graph(*city_trees(), {}); }, city_trees_optimum());
}
void BM_CityTrees_GraphSlamLandmarkSchur(benchmark::State& state) {
  if (require_city_trees(state))
    optimize_graph<PlanarGraph>(
        state, [] { return planar_graph(*city_trees(), {.solver = GraphSolver::landmark_schur}); }, city_trees_optimum());
}
void BM_CityTrees_CeresSparseSchur(benchmark::State& state) {
  if (require_city_trees(state))
    solve_with_ceres<3>(state, ceres::SPARSE_SCHUR, build_city_trees_peer, city_trees_optimum());
}
void BM_CityTrees_CeresSparseNormalCholesky(benchmark::State& state) {
  if (require_city_trees(state))
    solve_with_ceres<3>(state, ceres::SPARSE_NORMAL_CHOLESKY, build_city_trees_peer, city_trees_optimum());
}

/// GraphSLAM's online mode (one Gauss-Newton step a frame) over the whole ship, beside
/// BM_Ship_GraphSlam's batch optimize() of the same steps: the ship closes its loop after 1200 steps,
/// so its last frames reach back to the first poses (ProfileCholesky's sparse steps, counted).
/// Counters: the last 100 frames' mean and the largest frame, in ms.
void BM_Ship_GraphOnline(benchmark::State& state) {
  std::size_t sparse = 0;
  double last_100 = 0.0, largest = 0.0;
  for (auto _ : state) {
    ShipGraph graph{ship().motion, ship().sensor, ship().prior, {.incremental = true}};
    sparse = 0;
    last_100 = largest = 0.0;
    const auto& steps = ship().steps;
    for (std::size_t k = 0; k < steps.size(); ++k) {
      const auto start = std::chrono::steady_clock::now();
      graph.predict(steps[k].control, steps[k].dt);
      graph.update(steps[k].observations);
      const double ms = 1e3 * seconds_since(start);
      sparse += graph.last_online_step().sparse;
      largest = std::max(largest, ms);
      if (k + 100 >= steps.size()) last_100 += ms / 100.0;
    }
    benchmark::DoNotOptimize(graph.pose());
  }
  state.counters["sparse_steps"] = static_cast<double>(sparse);
  state.counters["last_100_ms"] = last_100;
  state.counters["largest_ms"] = largest;
}

/// A GraphSLAM run that asks for pose() after every step (what eval::run does): total time for
/// K steps must grow linearly in K (pose() is O(1); docs/benchmarks.md).
void BM_GraphSlamRunWithPoseEveryStep(benchmark::State& state) {
  const auto steps = static_cast<std::size_t>(state.range(0));
  sim::Ship2DOptions options;
  options.seed = 1;
  options.num_steps = static_cast<int>(steps);
  const auto data = sim::simulate_ship_2d(options);
  for (auto _ : state) {
    ShipGraph graph{data.motion, data.sensor, data.prior};
    benchmark::DoNotOptimize(eval::run(graph, data.steps));
  }
  state.counters["steps"] = static_cast<double>(steps);
  state.counters["us_per_step"] = benchmark::Counter(static_cast<double>(steps), benchmark::Counter::kIsIterationInvariantRate |
                                                                                     benchmark::Counter::kInvert);
}

}  // namespace

BENCHMARK(BM_Ship_GraphSlam)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Ship_GraphSlamLandmarkSchur)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Ship_GraphOnline)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Ship_CeresSparseSchur)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Ship_CeresSparseNormalCholesky)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_CityTrees_GraphSlam)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_CityTrees_GraphSlamLandmarkSchur)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_CityTrees_CeresSparseSchur)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_CityTrees_CeresSparseNormalCholesky)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_GraphSlamRunWithPoseEveryStep)->Arg(1000)->Arg(2000)->Arg(4000)->Unit(benchmark::kMillisecond);
BENCHMARK_MAIN();
