// sextant's PoseGraph beside the two optimizers a pose-graph user would otherwise pick, on the
// standard benchmarks (../shared/data/pose_graphs) and MRPT's 50-pose circle (mrpt-common), each
// from the same start (the file's vertices; manhattan's spanning tree of its odometry):
//  - sextant: PoseGraph::optimize() with its default options;
//  - MRPT: optimize_graph_spa_levmarq with its defaults on the graph its loader reads from the file
//    (tests/support/mrpt_pose_graph.hpp);
//  - Ceres 2.1: the formulation and solver options of its pose_graph_2d/3d examples
//    (tests/support/ceres_pose_graph.hpp).
// Time is each solver's own (manual time: MRPT's file loading is left out). Counters: chi2, the final
// g2o chi2 of every solver computed by one function (PoseGraph::chi2), and iterations; for sextant
// (run after its peers on each file) to_best_peer_ms, the time at which its chi2 first came within
// 1e-6 (relative) of the lowest final chi2 of the peers (-1: never).
// Run: pose_graph_benchmark --benchmark_counters_tabular=true; table in docs/results/pose_graphs.md.
#include <benchmark/benchmark.h>

#include <filesystem>
#include <map>
#include <memory>

#include "sextant/io/pose_graph_file.hpp"
#include "support/ceres_pose_graph.hpp"
#include "support/mrpt_pose_graph.hpp"

namespace {

using namespace sextant;

enum class Solver { sextant, mrpt, ceres };

/// The lowest final chi2 of the peers on each file so far.
std::map<std::string, double>& best_peer_chi2() {
  static std::map<std::string, double> best;
  return best;
}

const io::PoseGraphFile& start_of(const std::string& path) {
  static std::map<std::string, std::unique_ptr<io::PoseGraphFile>> files;
  auto& file = files[path];
  if (!file) file = std::make_unique<io::PoseGraphFile>(io::read_pose_graph(path));
  return *file;
}

template <class Poses>
void solve(benchmark::State& state, const std::string& path, const PoseGraph<Poses>& start, Solver solver) {
  double chi2 = 0.0, iterations = 0.0, to_best_peer_ms = -1.0;
  for (auto _ : state) {
    PoseGraph<Poses> graph = start;
    double seconds = 0.0;
    if (solver == Solver::sextant) {
      const auto summary = graph.optimize();
      seconds = summary.seconds;
      iterations = summary.iterations;
      to_best_peer_ms = -1.0;
      if (const auto best = best_peer_chi2().find(path); best != best_peer_chi2().end())
        for (std::size_t k = 0; k < summary.cost.size() && to_best_peer_ms < 0; ++k)
          if (summary.cost[k] <= best->second * (1.0 + 1e-6)) to_best_peer_ms = 1e3 * summary.cost_at[k];
    } else if (solver == Solver::mrpt) {
      const auto result = test::solve_with_mrpt(graph);
      seconds = result.seconds;
      iterations = static_cast<double>(result.iterations);
    } else {
      const auto result = test::solve_with_ceres(graph);
      seconds = result.seconds;
      iterations = static_cast<double>(result.summary.iterations.size() - 1);
    }
    state.SetIterationTime(seconds);
    chi2 = graph.chi2();
  }
  if (solver == Solver::sextant) {
    state.counters["to_best_peer_ms"] = to_best_peer_ms;
  } else {
    auto [best, inserted] = best_peer_chi2().emplace(path, chi2);
    if (!inserted) best->second = std::min(best->second, chi2);
  }
  state.counters["chi2"] = chi2;
  state.counters["iterations"] = iterations;
  state.counters["initial_chi2"] = start.chi2();
}

void register_file(const std::string& name, const std::string& path) {
  if (!std::filesystem::exists(path)) return;
  for (auto [solver, solver_name] : {std::pair{Solver::mrpt, "mrpt"}, {Solver::ceres, "ceres"}, {Solver::sextant, "sextant"}})
    benchmark::RegisterBenchmark(("BM_PoseGraph/" + name + "/" + solver_name).c_str(),
                                 [path, solver = solver](benchmark::State& state) {
                                   const auto& file = start_of(path);
                                   if (file.dimension == 2) solve(state, path, file.planar, solver);
                                   else solve(state, path, file.spatial, solver);
                                 })
        ->UseManualTime()
        ->Iterations(3)
        ->Unit(benchmark::kMillisecond);
}

}  // namespace

int main(int argc, char** argv) {
  const std::string shared = std::string(SEXTANT_SHARED_DATA_DIR) + "/pose_graphs/";
  register_file("circle50", "/usr/share/mrpt/datasets/graph_2d_circle_50nodes.graph");
  for (const char* name : {"intel", "manhattan", "city10000", "sphere2500", "parking-garage"})
    register_file(name, shared + name + ".g2o");
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
}
