// GraphSLAM's optimize() beside Ceres (SPARSE_SCHUR and SPARSE_NORMAL_CHOLESKY, SuiteSparse, one
// thread) on the same problems from the same starting point, each solved to the same final cost
// (reported as the chi2 counter): the 1390-step ship and cityTrees10000 (../shared/data).
#include <benchmark/benchmark.h>

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

template <class Graph, class Make>
void optimize_graph(benchmark::State& state, Make make) {
  double cost = 0.0;
  int iterations = 0;
  for (auto _ : state) {
    state.PauseTiming();
    Graph graph = make();
    state.ResumeTiming();
    const auto summary = graph.optimize();
    state.PauseTiming();
    cost = summary.cost.back();
    iterations = summary.iterations;
    state.ResumeTiming();
  }
  state.counters["chi2"] = cost;
  state.counters["iterations"] = iterations;
}

template <int X, class Build>
void solve_with_ceres(benchmark::State& state, ceres::LinearSolverType type, Build build) {
  double cost = 0.0;
  int iterations = 0;
  for (auto _ : state) {
    state.PauseTiming();
    auto peer = std::make_unique<test::CeresGraph<X>>();
    build(*peer);
    state.ResumeTiming();
    const auto summary = peer->solve(type);
    state.PauseTiming();
    cost = 2.0 * summary.final_cost;  // Ceres reports chi2 / 2
    iterations = static_cast<int>(summary.iterations.size());
    peer.reset();
    state.ResumeTiming();
  }
  state.counters["chi2"] = cost;
  state.counters["iterations"] = iterations;
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

// The ship.
void BM_Ship_GraphSlam(benchmark::State& state) { optimize_graph<ShipGraph>(state, [] { return ship_graph({}); }); }
void BM_Ship_GraphSlamLandmarkSchur(benchmark::State& state) {
  optimize_graph<ShipGraph>(state, [] { return ship_graph({.solver = GraphSolver::landmark_schur}); });
}
void BM_Ship_CeresSparseSchur(benchmark::State& state) { solve_with_ceres<2>(state, ceres::SPARSE_SCHUR, build_ship_peer); }
void BM_Ship_CeresSparseNormalCholesky(benchmark::State& state) {
  solve_with_ceres<2>(state, ceres::SPARSE_NORMAL_CHOLESKY, build_ship_peer);
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
  if (require_city_trees(state)) optimize_graph<PlanarGraph>(state, [] { return planar_graph(*city_trees(), {}); });
}
void BM_CityTrees_GraphSlamLandmarkSchur(benchmark::State& state) {
  if (require_city_trees(state))
    optimize_graph<PlanarGraph>(state, [] { return planar_graph(*city_trees(), {.solver = GraphSolver::landmark_schur}); });
}
void BM_CityTrees_CeresSparseSchur(benchmark::State& state) {
  if (require_city_trees(state)) solve_with_ceres<3>(state, ceres::SPARSE_SCHUR, build_city_trees_peer);
}
void BM_CityTrees_CeresSparseNormalCholesky(benchmark::State& state) {
  if (require_city_trees(state)) solve_with_ceres<3>(state, ceres::SPARSE_NORMAL_CHOLESKY, build_city_trees_peer);
}

}  // namespace

BENCHMARK(BM_Ship_GraphSlam)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Ship_GraphSlamLandmarkSchur)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Ship_CeresSparseSchur)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Ship_CeresSparseNormalCholesky)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_CityTrees_GraphSlam)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_CityTrees_GraphSlamLandmarkSchur)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_CityTrees_CeresSparseSchur)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_CityTrees_CeresSparseNormalCholesky)->Unit(benchmark::kMillisecond);
BENCHMARK_MAIN();
