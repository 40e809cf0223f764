// sextant-run's globe part: the thesis's visual SLAM experiment (seed 000, §4.2.2, §5.2): the
// 12D Euler-angle camera circling a simulated globe, every back-end through the bounded landmark
// pool, one row per back-end as in Tables 8-10.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <optional>
#include <sextant/eval/camera_scores.hpp>
#include <sextant/eval/metrics.hpp>
#include <sextant/eval/pooled_run.hpp>
#include <sextant/io/csv_writer.hpp>
#include <sextant/io/tum_writer.hpp>
#include <sextant/mrpt/scene.hpp>
#include <sextant/sim/globe_camera.hpp>
#include <string>
#include <vector>

#include "backend_factory.hpp"
#include "dataset_registry.hpp"
#include "globe_runs.hpp"
#include "plot_script.hpp"
#include "progress_bar.hpp"
#include "runner_config.hpp"
#include "table.hpp"

namespace sextant::runner {

sim::GlobeCameraOptions globe_options(const GlobeSettings& s) {
  sim::GlobeCameraOptions o;
  o.seed = s.seed;
  o.num_steps = s.steps;
  o.num_points = s.points;
  o.max_features_per_frame = s.features_per_frame;
  o.response_jitter = s.response_jitter;
  return o;
}

namespace {

using Dataset = sim::GlobeCameraDataset;
using Motion = EulerCamera12D;
using Sensor = PointInCamera3D;
using SampledPoses = std::vector<eval::SampledPose<Gaussian<Vector12d, 12>>>;

/// One back-end configuration's run on the globe, scored.
struct GlobeRun {
  std::string key, label;
  eval::CameraSummary summary;
  eval::CameraScores scores;
  std::vector<Vector12d> means;
  std::vector<PoolStepRecord> pool;
  std::vector<LandmarkEstimate<3>> map;
  double total_seconds = 0.0;
  std::vector<double> step_seconds;  ///< each frame's predict + pool + update (GraphSLAM: recording it)
  std::vector<double> graph_update_seconds;       ///< GraphSLAM: each global update
  std::vector<double> graph_update_position_mae;  ///< GraphSLAM: position MAE after each global update
  double marginal_seconds = 0.0;                  ///< GraphSLAM: recovering the marginals for the NEES
  std::vector<std::size_t> nees_steps;            ///< the step of each pose NEES in scores
  eval::StepFailures failures;                    ///< steps that failed and were skipped
  std::optional<std::string> failure;             ///< why the back-end as a whole gave no result
  std::optional<RelocalizationRow> relocalization;  ///< ESEIF's relocalizations over the run
  std::optional<OptimizationRow> optimization;      ///< GraphSLAM: how its last global update ended
};

/// The landmarks of `map` that have a true point (a rendered front-end may propose a landmark whose
/// first keypoint lies off the globe: it has none and is not scored).
std::vector<LandmarkEstimate<3>> with_truth(std::vector<LandmarkEstimate<3>> map, const Dataset& data) {
  std::erase_if(map, [&](const LandmarkEstimate<3>& l) { return !data.true_landmarks.contains(l.id); });
  return map;
}

template <class Backend>
GlobeRun run_filter(Backend& backend, const Dataset& data, const RunnerConfig& c, std::string key, std::string label) {
  ProgressBar progress("globe: " + key, data.steps.size());
  auto run = eval::run_through_pool(
      backend, data.steps, c.globe.pool, c.globe.covariance_period,
      [&](std::size_t, const Backend&) { progress.advance(); }, eval::StepErrors::skip);
  GlobeRun out;
  out.key = std::move(key);
  out.label = std::move(label);
  out.failures = run.failures;
  out.map = with_truth(backend.map(), data);
  out.scores = eval::score_camera(run.means, run.poses, data.true_poses, out.map, data.true_landmarks);
  out.summary = eval::summarize_camera(out.scores);
  out.means = std::move(run.means);
  out.pool = std::move(run.pool);
  out.total_seconds = run.total_seconds;
  out.step_seconds = std::move(run.seconds);
  for (const auto& sampled : run.poses) out.nees_steps.push_back(sampled.step);
  out.relocalization = relocalization_row(backend, data.steps.size());
  return out;
}

/// GraphSLAM's NEES: the smoothed marginals of the optimum (every pose from all the frames), at the
/// steps where the filters' covariances are sampled, and the map's. Their time is not the update's.
template <class Graph>
void score_smoothed_marginals(const Graph& graph, const Dataset& data, const RunnerConfig& c, GlobeRun& out) {
  const auto start = std::chrono::steady_clock::now();
  const auto trajectory = graph.trajectory();
  SampledPoses sampled;
  for (std::size_t k = 0; k < out.means.size(); ++k)
    if (eval::is_sampled_step(k, out.means.size(), c.globe.covariance_period)) {
      sampled.push_back({k, trajectory[k + 1]});
      out.nees_steps.push_back(k);
    }
  out.map = with_truth(graph.map(), data);
  out.scores = eval::score_camera(out.means, sampled, data.true_poses, out.map, data.true_landmarks);
  out.summary = eval::summarize_camera(out.scores);
  out.marginal_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

/// GraphSLAM as the thesis ran it (globe_choices): the steps recorded through the pool, then
/// windowed initialization and global Gauss-Newton updates, scored after each (Table 10); the row
/// gives the last.
template <class Graph>
GlobeRun run_graph(Graph& graph, const Dataset& data, const RunnerConfig& c, std::string key, std::string label) {
  ProgressBar progress("globe: " + key, data.steps.size() + static_cast<std::size_t>(c.globe.graph_updates));
  auto run = eval::run_through_pool(
      graph, data.steps, c.globe.pool, 0, [&](std::size_t, const Graph&) { progress.advance(); },
      eval::StepErrors::skip);
  GlobeRun out;
  out.key = std::move(key);
  out.label = std::move(label);
  out.failures = run.failures;
  out.pool = std::move(run.pool);
  out.total_seconds = run.total_seconds;
  out.step_seconds = std::move(run.seconds);
  for (int update = 0; update < c.globe.graph_updates; ++update) {
    const auto start = std::chrono::steady_clock::now();
    const auto summary = graph.optimize();
    out.optimization = optimization_row(summary);
    out.graph_update_seconds.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    out.total_seconds += out.graph_update_seconds.back();
    // Means after each update (Table 10); the marginals once, after the last.
    std::vector<Vector12d> means(graph.pose_means().begin() + 1, graph.pose_means().end());
    out.map.clear();
    for (const auto& [id, mean] : graph.landmark_means()) out.map.push_back({id, mean, Eigen::Matrix3d::Zero()});
    out.map = with_truth(std::move(out.map), data);
    out.scores = eval::score_camera(means, SampledPoses{}, data.true_poses, out.map, data.true_landmarks, false);
    out.summary = eval::summarize_camera(out.scores);
    out.means = std::move(means);
    out.graph_update_position_mae.push_back(out.summary.position_mae);
    progress.advance();
  }
  if (c.globe.covariance_period > 0 && !out.means.empty()) score_smoothed_marginals(graph, data, c, out);
  return out;
}

/// The globe's back-end configurations: SEIF once per [globe] seif_active, ESEIF once per [globe]
/// eseif_active; GraphSLAM as the thesis
/// ran it, windowed initialization (windows of 50 steps, 5 iterations each), then one global update
/// per optimize(), and/or online ([globe] graph).
std::vector<BackendChoice> globe_choices(const std::vector<BackendKind>& kinds, const RunnerConfig& c) {
  std::vector<BackendChoice> choices;
  for (auto choice : backend_choices<Motion>(kinds, c)) {
    if (choice.kind == BackendKind::seif || choice.kind == BackendKind::eseif) {
      const bool relocalizing = choice.seif.sparsification == SeifSparsification::relocalization;
      for (std::size_t active : choice.kind == BackendKind::seif ? c.globe.seif_active : c.globe.eseif_active) {
        BackendChoice seif = choice;
        const std::string name = active ? std::to_string(active) : "all";
        seif.seif.max_active = active;
        seif.key = (relocalizing ? "eseif" : "seif") + name;
        seif.label = seif_label(relocalizing, active);
        choices.push_back(std::move(seif));
      }
      continue;
    }
    if (choice.kind == BackendKind::graph) {
      BackendChoice online = choice;
      choice.graph.max_iterations = 1;
      choice.graph.window = 50;
      choice.graph.window_iterations = 5;
      choice.label = "GraphSLAM, windows 50 x 5";
      if (c.globe.graph_batch) choices.push_back(choice);
      online.graph.incremental = true;
      online.graph.lag = c.globe.graph_lag;
      online.key = "graph_online";
      online.label = c.globe.graph_lag > 0 ? "GraphSLAM, lag " + std::to_string(c.globe.graph_lag) : "GraphSLAM, online";
      if (c.globe.graph_online) choices.push_back(std::move(online));
      continue;
    }
    choices.push_back(std::move(choice));
  }
  return choices;
}

std::vector<GlobeRun> run_backends(const Dataset& data, const std::vector<BackendKind>& kinds, const RunnerConfig& c) {
  std::vector<GlobeRun> runs;
  for (const auto& choice : globe_choices(kinds, c)) {
    const auto failure = failure_of([&] {
      with_backend(choice, data.motion, data.sensor, data.prior, [&](auto& backend) {
        if constexpr (requires { backend.optimize(); })  // online: run and scored as a filter is
          runs.push_back(choice.graph.incremental ? run_filter(backend, data, c, choice.key, choice.label)
                                                  : run_graph(backend, data, c, choice.key, choice.label));
        else
          runs.push_back(run_filter(backend, data, c, choice.key, choice.label));
      });
    });
    if (failure) runs.push_back(failed_run<GlobeRun>(choice, *failure));  // its row says so; the others still run
  }
  return runs;
}

/// The q-quantile of `values` (nearest rank), NaN for none.
double quantile(std::vector<double> values, double q) {
  if (values.empty()) return std::numeric_limits<double>::quiet_NaN();
  const auto at = static_cast<std::size_t>(std::ceil(q * static_cast<double>(values.size()))) - 1;
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(at), values.end());
  return values[at];
}

/// Issue 37's real-time figures per row: milliseconds per frame, median, 95th percentile and the last
/// frame (a filter's frame: predict, the pool, update; GraphSLAM records the frame and optimizes in
/// global updates, whose mean is printed beside).
void print_frame_times(const std::vector<GlobeRun>& runs) {
  std::printf("%-27s %12s %12s %12s\n", "ms per frame", "median", "95th pct", "last");
  for (const auto& r : runs) {
    if (r.failure || r.step_seconds.empty()) continue;
    std::printf("%-27s %12.2f %12.2f %12.2f", r.label.c_str(), 1e3 * quantile(r.step_seconds, 0.5),
                1e3 * quantile(r.step_seconds, 0.95), 1e3 * r.step_seconds.back());
    if (!r.graph_update_seconds.empty()) {
      double sum = 0.0;
      for (double t : r.graph_update_seconds) sum += t;
      std::printf("   recording only; then %zu global updates, %.1f ms each",
                  r.graph_update_seconds.size(), 1e3 * sum / static_cast<double>(r.graph_update_seconds.size()));
    }
    std::printf("\n");
  }
}

void print_globe_header() {
  std::printf("%-27s %9s %9s %9s %9s %9s %9s %9s %9s %9s %9s %10s\n", "back-end", "pos [mm]", "aligned", "rot [rad]",
              "map [mm]", "aligned", "pos NEES", "rot NEES", "map NEES", "pos ANEES", "total [s]", "step [ms]");
}

void print_globe_row(const GlobeRun& r, std::size_t steps) {
  if (r.failure) {
    std::printf("%-27s failed: %s\n", r.label.c_str(), r.failure->c_str());
    return;
  }
  const auto& s = r.summary;
  auto share = [](double fraction) {
    char text[16];
    if (std::isnan(fraction)) return std::string("-");
    std::snprintf(text, sizeof text, "%.0f%%", 100 * fraction);
    return std::string(text);
  };
  auto number = [](double value) {
    char text[32];
    if (std::isnan(value)) return std::string("-");
    std::snprintf(text, sizeof text, "%.4g", value);
    return std::string(text);
  };
  std::printf("%-27s %9.2f %9.2f %9.4f %9.2f %9.2f %9s %9s %9s %9s %9.1f %10.2f\n", r.label.c_str(),
              1e3 * s.position_mae, 1e3 * s.position_mae_aligned, s.rotation_mae, 1e3 * s.map_mae,
              1e3 * s.map_mae_aligned, share(s.position_nees_inside).c_str(), share(s.rotation_nees_inside).c_str(),
              share(s.map_nees_inside).c_str(), number(s.position_anees).c_str(), r.total_seconds,
              1e3 * r.total_seconds / static_cast<double>(steps));
  if (r.relocalization) print_relocalization(27, *r.relocalization);
  if (r.optimization) print_optimization(27, *r.optimization);
  print_skipped_steps(27, r.failures.total(), "step", r.failures.first);
}

TableRow table_row(const GlobeRun& r, std::size_t steps) {
  eval::Summary s;
  s.pose_mae = r.summary.position_mae;
  s.pose_mae_aligned = r.summary.position_mae_aligned;
  s.map_mae = r.summary.map_mae;
  s.map_mae_aligned = r.summary.map_mae_aligned;
  s.pose_nees_inside = r.summary.position_nees_inside;
  s.map_nees_inside = r.summary.map_nees_inside;
  s.pose_anees = r.summary.position_anees;
  s.total_seconds = r.total_seconds;
  s.seconds_per_step = r.total_seconds / static_cast<double>(steps);
  s.failed_steps = r.failures.total();
  s.first_failure = r.failures.first;
  TableRow row{.dataset = "globe", .backend = r.key, .label = r.label, .summary = s, .relocalization = r.relocalization,
               .optimization = r.optimization};
  if (r.failure) {
    row.summary.mark_unscored();
    row.failure = r.failure;
  }
  return row;
}

void write_globe_outputs(const RunOptions& options, const std::string& name, const Dataset& data,
                         const std::vector<GlobeRun>& runs, const RunnerConfig& c) {
  if (options.out.empty()) return;
  const auto dir = std::filesystem::path(options.out) / name;
  std::filesystem::create_directories(dir);
  std::vector<io::TumPose> truth;
  for (std::size_t k = 1; k < data.true_poses.size(); ++k)
    truth.push_back({data.steps[0].dt * static_cast<double>(k), data.true_poses[k].head<3>(),
                     Eigen::Quaterniond(euler_yxz::rotation(data.true_poses[k].segment<3>(3)))});
  io::write_tum((dir / "ground_truth.tum").string(), truth);
  for (const auto& r : runs) {
    if (r.failure) continue;
    io::CsvWriter csv((dir / (r.key + "_steps.csv")).string(),
                      {"step", "position_error", "rotation_error", "in_pool", "added", "evicted", "refused", "seconds"});
    for (std::size_t k = 0; k < r.means.size(); ++k) {
      const PoolStepRecord pool = k < r.pool.size() ? r.pool[k] : PoolStepRecord{};
      csv.row({static_cast<double>(k + 1), r.scores.position_error[k], r.scores.rotation_error[k],
               static_cast<double>(pool.in_pool), static_cast<double>(pool.added), static_cast<double>(pool.evicted),
               static_cast<double>(pool.refused), k < r.step_seconds.size() ? r.step_seconds[k] : 0.0});
    }
    std::vector<io::TumPose> estimate;
    mrpt_io::SceneContent scene;
    for (std::size_t k = 0; k < r.means.size(); ++k) {
      estimate.push_back({data.steps[0].dt * static_cast<double>(k + 1), r.means[k].head<3>(),
                          Eigen::Quaterniond(euler_yxz::rotation(r.means[k].segment<3>(3)))});
      scene.estimated_path.push_back(r.means[k].head<3>());
      scene.true_path.push_back(data.true_poses[k + 1].head<3>());
    }
    io::write_tum((dir / (r.key + "_trajectory.tum")).string(), estimate);
    if (!r.nees_steps.empty()) {
      io::CsvWriter nees((dir / (r.key + "_nees.csv")).string(), {"step", "position_nees", "rotation_nees"});
      for (std::size_t i = 0; i < r.nees_steps.size(); ++i)
        nees.row({static_cast<double>(r.nees_steps[i] + 1), r.scores.position_nees[i], r.scores.rotation_nees[i]});
    }
    scene.landmarks = mrpt_io::scene_landmarks(r.map);
    for (const auto& [id, p] : data.true_landmarks) scene.true_landmarks.push_back(p);
    mrpt_io::write_scene((dir / (r.key + ".3Dscene")).string(), scene, {.quantile = c.scene_quantile});
  }
  std::printf("wrote per-step CSV (errors and pool bookkeeping), NEES CSV, TUM trajectories and .3Dscene files to %s\n",
              dir.c_str());
  if (!options.plots) return;
  run_plot_script("plot_globe.py", dir);
}

}  // namespace

std::vector<TableRow> run_globe_dataset(const RunOptions& options, const std::string& name, const sim::GlobeCameraDataset& data,
                                        const std::vector<BackendKind>& kinds, const RunnerConfig& config) {
  const auto runs = run_backends(data, kinds, config);
  print_globe_header();
  std::vector<TableRow> rows;
  for (const auto& r : runs) {
    print_globe_row(r, data.steps.size());
    rows.push_back(table_row(r, data.steps.size()));
    rows.back().dataset = name;
  }
  print_frame_times(runs);
  for (const auto& r : runs) {
    if (r.graph_update_position_mae.empty()) continue;
    std::printf("GraphSLAM position MAE [mm] after each global update:");
    for (double mae : r.graph_update_position_mae) std::printf(" %.2f", 1e3 * mae);
    std::printf("\nGraphSLAM NEES: smoothed marginals of the optimum (%.1f s to recover, not in its time)\n",
                r.marginal_seconds);
  }
  std::printf("NEES columns: share of sampled steps (every %zu-th; landmarks for the map) inside the 95%% chi-square "
              "bound with 3 dof (7.81); rot: NEES of the rotation vector Log(R^T R_est). Pool at the end: ",
              config.globe.covariance_period);
  if (!runs.empty() && !runs.front().pool.empty()) {
    std::size_t added = 0, evicted = 0;
    for (const auto& p : runs.front().pool) {
      added += p.added;
      evicted += p.evicted;
    }
    std::printf("%zu landmarks, %zu added, %zu evicted (%s).\n", runs.front().pool.back().in_pool, added, evicted,
                runs.front().label.c_str());
  } else {
    std::printf("-\n");
  }
  write_globe_outputs(options, name, data, runs, config);
  return rows;
}

/// How far the prior's mean lies from the true first pose: the global frame is unobservable, so no
/// frame corrects that draw and every step's pose NEES carries it (docs/results/real_time.md, "Frames/s
/// with the slant settings": the runs whose share inside is low are the seeds whose draw is large).
void print_start_draw(const sim::GlobeCameraDataset& data) {
  const Eigen::Vector3d error = data.prior.mean.head<3>() - data.true_poses.front().head<3>();
  const double nees = eval::nees(error, data.prior.cov.topLeftCorner<3, 3>());
  std::printf("The start: the prior's position is %.2f mm off the true first pose, NEES %.2f under the prior (3 dof; the "
              "global frame is unobservable, so every step's pose NEES carries this draw).\n",
              1e3 * error.norm(), nees);
}

namespace {

std::vector<TableRow> run_globe(const CliOptions& cli, const std::string&, const std::vector<BackendKind>& kinds,
                                const RunnerConfig& config) {
  const auto data = sim::simulate_globe_camera(globe_options(config.globe));
  std::printf("\n== globe: the thesis's 12D camera around a simulated globe, %d steps, %zu points, %d features per "
              "frame, pool Mmax = %zu, max_new = %zu; seed %llu\n",
              config.globe.steps, data.true_landmarks.size(), config.globe.features_per_frame,
              config.globe.pool.max_landmarks, config.globe.pool.max_new_per_step,
              static_cast<unsigned long long>(config.globe.seed));
  auto rows = run_globe_dataset(cli.output, "globe", data, kinds, config);
  print_start_draw(data);
  return rows;
}

const RegisterDatasetRun registration{"globe", run_globe};

}  // namespace

}  // namespace sextant::runner
