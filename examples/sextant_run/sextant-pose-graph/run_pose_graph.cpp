// sextant-run's pose-graph part (--dataset FILE.g2o | FILE.graph): reads a 2D or 3D pose graph in
// g2o or TORO/MRPT format, optimizes it from the start [pose_graph] start names, and prints its
// size, the chi2 before and after, iterations, time and why it stopped; with --out it writes the
// optimized graph as <name>_optimized.g2o, with --plots a PNG of it (2D: the trajectory and the
// loop closures; 3D: the trajectory seen from above).
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <sextant/io/pose_graph_file.hpp>

#include "dataset_registry.hpp"
#include "plot_script.hpp"
#include "runner_config.hpp"

namespace sextant::runner {

namespace {

const char* start_name(PoseGraphStart start, bool spanning_tree_start) {
  switch (start) {
    case PoseGraphStart::spanning_tree: return "spanning tree of the odometry";
    case PoseGraphStart::chordal: return "chordal relaxation";
    case PoseGraphStart::file: break;
  }
  return spanning_tree_start ? "spanning tree of the odometry (the file has no vertices)" : "the file's vertices";
}

template <class Poses>
void describe(const std::string& path, const io::PoseGraphFile& file, const PoseGraph<Poses>& graph) {
  std::size_t odometry = 0, loops = 0;
  for (const auto& edge : graph.betweens()) (edge.edge_class == EdgeClass::odometry ? odometry : loops)++;
  std::printf("\n%s: %dD %s pose graph (%s): %zu poses, %zu points; %zu edges: %zu odometry, %zu loop closures, "
              "%zu priors, %zu point observations\n",
              path.c_str(), file.dimension, file.format.c_str(), Poses::name, graph.num_poses(), graph.num_points(),
              graph.num_edges(), odometry, loops, graph.priors().size(), graph.observations().size());
}

template <class Poses>
void optimize_and_report(const CliOptions& cli, const std::string& path, const io::PoseGraphFile& file,
                         PoseGraph<Poses>& graph, const RunnerConfig& config) {
  describe(path, file, graph);
  const auto began = std::chrono::steady_clock::now();
  if (config.pose_graph_start == PoseGraphStart::spanning_tree) graph.initialize_by_spanning_tree();
  if (config.pose_graph_start == PoseGraphStart::chordal) graph.initialize_by_chordal_relaxation();
  const double start_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - began).count();
  const double start_chi2 = graph.chi2();
  const auto summary = graph.optimize(config.pose_graph);
  std::printf("\n| start | chi2 at start | final chi2 | iterations (accepted) | start s | optimize s | stopped |\n"
              "|---|---|---|---|---|---|---|\n| %s | %.10g | %.10g | %d (%d) | %.3f | %.3f | %s |\n",
              start_name(config.pose_graph_start, file.spanning_tree_start), start_chi2, summary.final_chi2,
              summary.iterations, summary.accepted, start_seconds, summary.seconds, summary.stop_reason.c_str());
  if (summary.final_cost != summary.final_chi2 || summary.rejected_edges > 0)
    std::printf("robust cost (minimized): %.10g -> %.10g; edges rejected by the outlier gate: %zu (the chi2 above leaves them out)\n",
                summary.initial_cost, summary.final_cost, summary.rejected_edges);
  std::printf("chi2: sum of e^T Omega e over the edges with g2o's errors; time per stage: normal equations %.3f s, "
              "factorization and solve %.3f s, trial costs %.3f s\n",
              summary.seconds_linearize, summary.seconds_solve, summary.seconds_evaluate);
  if (cli.output.out.empty()) return;
  std::filesystem::create_directories(cli.output.out);
  const auto written = std::filesystem::path(cli.output.out) / (std::filesystem::path(path).stem().string() + "_optimized.g2o");
  io::write_g2o(written.string(), graph);
  std::printf("wrote %s\n", written.c_str());
  if (cli.output.plots) run_plot_script("plot_pose_graph.py", cli.output.out, "'" + written.filename().string() + "'");
}

std::vector<TableRow> run_pose_graph(const CliOptions& cli, const std::string& path, const std::vector<BackendKind>&,
                                     const RunnerConfig& config) {
  io::PoseGraphFile file = io::read_pose_graph(path);
  if (file.dimension == 2) optimize_and_report(cli, path, file, file.planar, config);
  else optimize_and_report(cli, path, file, file.spatial, config);
  return {};
}

const RegisterDatasetRun registration{"pose-graph", run_pose_graph};

}  // namespace
}  // namespace sextant::runner
