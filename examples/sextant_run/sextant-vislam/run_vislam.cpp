// sextant-vislam's runs: seed 004's visual-inertial SLAM on SE(3) (IMU velocities, stereo pixel
// pairs) on a KITTI-derived .npz file or on the simulated stereo car, every back-end through the
// landmark pool, against dead reckoning. Scored against the truth (stereo-vi) or, for
// <name>_noisy.npz with <name>_clean.npz beside it, against the clean file's dead reckoning.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <optional>
#include <sextant/eval/dead_reckoning.hpp>
#include <sextant/eval/pooled_run.hpp>
#include <sextant/io/csv_writer.hpp>
#include <sextant/io/tum_writer.hpp>
#include <sextant/io/visual_inertial_npz.hpp>
#include <sextant/mrpt/scene.hpp>
#include <sextant/sim/stereo_vi.hpp>
#include <string>
#include <vector>

#include "backend_factory.hpp"
#include "plot_script.hpp"
#include "progress_bar.hpp"
#include "runner_config.hpp"
#include "table.hpp"
#include "dataset_registry.hpp"

namespace sextant::runner {
namespace {

using Motion = ImuVelocitySe3;
using Sensor = StereoPixelsSe3;
using Frame = Step<se3::Vector6d, Eigen::Vector4d>;

/// A data set as the back-ends see it, with what it is scored against.
struct ViData {
  std::string name;
  Motion motion;
  Sensor sensor;
  Gaussian<Eigen::Matrix4d, 6> prior;
  std::vector<Frame> frames;
  std::vector<double> times;                  ///< time stamp of each frame's pose [s]
  std::vector<Eigen::Matrix4d> reference;     ///< pose after each frame; empty: none
  bool reference_is_truth = false;            ///< the simulator's truth (NEES) or another estimate
  std::string reference_label;
  std::map<LandmarkId, Eigen::Vector3d> true_landmarks;
};

/// One back-end's run, scored.
struct ViRun {
  std::string key, label;
  std::vector<Eigen::Matrix4d> means;
  std::vector<eval::SampledPose<Gaussian<Eigen::Matrix4d, 6>>> poses;
  std::vector<LandmarkEstimate<3>> map;
  std::size_t in_state = 0;
  eval::UpdateTotals updates;  ///< mapped (initialized), corrected, gated (rejected), unusable
  double seconds = 0.0;
  double rmse = std::nan(""), anees = std::nan("");
  eval::StepFailures failures;         ///< frames whose predict or update failed and were skipped
  std::optional<std::string> failure;  ///< why the back-end as a whole gave no result
  std::optional<OptimizationRow> optimization;  ///< GraphSLAM: how its optimization ended
};

ViData simulated(const RunnerConfig& c) {
  const auto sim = sim::simulate_stereo_vi({.seed = c.vislam.seed, .num_steps = c.vislam.steps});
  ViData d{"stereo-vi", sim.motion, sim.sensor, sim.prior, sim.steps, {}, {}, true, "truth", sim.true_landmarks};
  for (std::size_t k = 0; k < d.frames.size(); ++k) d.times.push_back(d.frames[0].dt * static_cast<double>(k + 1));
  d.reference.assign(sim.true_poses.begin() + 1, sim.true_poses.end());
  return d;
}

/// <dir>/<name>_clean.npz beside <dir>/<name>_noisy.npz, if there is one.
std::optional<std::filesystem::path> clean_twin(const std::filesystem::path& path) {
  const std::string stem = path.stem().string();
  const std::string suffix = "_noisy";
  if (stem.size() <= suffix.size() || stem.compare(stem.size() - suffix.size(), suffix.size(), suffix) != 0) return {};
  const auto twin = path.parent_path() / (stem.substr(0, stem.size() - suffix.size()) + "_clean.npz");
  return std::filesystem::exists(twin) ? std::optional(twin) : std::nullopt;
}

/// The dead reckoning of the clean file beside a noisy one as the reference: only with as many
/// frames (else a note says why there is none), and with a warning when its time stamps differ.
void use_clean_twin(ViData& d, const io::VisualInertialDataset& data, const io::VisualInertialDataset& clean,
                    const std::filesystem::path& twin) {
  const std::string name = twin.filename().string();
  if (clean.steps.size() != data.steps.size()) {
    std::printf("note: %s has %zu frames, %s %zu: no reference\n", name.c_str(), clean.steps.size() + 1, d.name.c_str(),
                data.steps.size() + 1);
    return;
  }
  double shift = 0.0;
  for (std::size_t k = 0; k < data.time_stamps.size(); ++k)
    shift = std::max(shift, std::abs(clean.time_stamps[k] - data.time_stamps[k]));
  if (shift > 1e-6)
    std::printf("warning: the time stamps of %s differ from those of %s by up to %.6g s; its dead reckoning is the "
                "reference all the same\n", name.c_str(), d.name.c_str(), shift);
  d.reference = eval::dead_reckoning(d.motion, Eigen::Matrix4d(Eigen::Matrix4d::Identity()), clean.steps);
  d.reference_label = "dead reckoning of " + name;
}

ViData from_npz(const std::string& path, const RunnerConfig& c) {
  const auto data = io::read_visual_inertial_npz(path);
  print_warnings(data.implausible);
  ViData d;
  d.name = std::filesystem::path(path).filename().string();
  const double v = c.vislam.velocity_sigma, w = c.vislam.rate_sigma;
  d.motion.W.diagonal() << v * v, v * v, v * v, w * w, w * w, w * w;
  d.sensor.calibration = data.calibration;
  d.sensor.cam_T_imu = data.cam_T_imu;
  d.sensor.pixel_sigma = c.vislam.pixel_sigma;
  d.sensor.min_disparity = c.vislam.min_disparity;
  d.prior = {Eigen::Matrix4d::Identity(), 1e-8 * se3::Matrix6d::Identity()};  // the map's frame is the first pose
  d.frames = data.steps;
  d.times.assign(data.time_stamps.begin() + 1, data.time_stamps.end());
  if (const auto twin = clean_twin(path)) use_clean_twin(d, data, io::read_visual_inertial_npz(twin->string()), *twin);
  return d;
}

template <class Backend>
ViRun run_backend(Backend& backend, const ViData& d, PoolLimits pool, std::size_t covariance_period, std::string key,
                  std::string label) {
  ProgressBar progress(d.name + ": " + key, d.frames.size());
  auto run = eval::run_through_pool(
      backend, d.frames, pool, covariance_period, [&](std::size_t, const Backend&) { progress.advance(); },
      eval::StepErrors::skip);
  ViRun out;
  out.failures = run.failures;
  out.key = std::move(key);
  out.label = std::move(label);
  out.means = std::move(run.means);
  out.poses = std::move(run.poses);
  out.updates = run.updates;
  out.seconds = run.total_seconds;
  out.in_state = backend.num_landmarks();
  if constexpr (requires { backend.map(); }) out.map = backend.map();
  return out;
}

/// The graph's estimate replaced by a filter's: its pose after every frame, and its map where it still
/// holds a landmark; GraphSlam::warm_start places the others, which its pool let go, from their first
/// sighting at the filter's pose then.
template <class Graph>
void warm_start_from(Graph& graph, const ViRun& filter) {
  std::vector<typename Graph::State> poses{graph.pose_means().front()};
  poses.insert(poses.end(), filter.means.begin(), filter.means.end());
  typename Graph::MapEstimate map;
  for (const auto& landmark : filter.map)
    if (graph.has_landmark(landmark.id)) map.push_back(landmark);
  graph.warm_start(poses, map);
}

/// GraphSLAM: the frames recorded through the pool, then one optimization of the whole graph, with
/// Levenberg-Marquardt: from dead reckoning tens of metres off (0027_noisy.npz), plain Gauss-Newton
/// overshoots, its cost grows 10^4-fold in three steps and the system stops being positive definite.
/// The filters gate outliers; the graph down-weights them with a Huber loss at the same chi-square
/// quantile (4 dof). No pool: a sparse graph does not need one, and a landmark marginalized while
/// the poses are still dead reckoning would fix its factor at that linearization point.
/// (vislam_choices sets the options.)
/// With `start`, the optimization starts from a filter's run instead of dead reckoning (warm_start_from).
template <class Graph>
ViRun run_graph(Graph& graph, const ViData& d, std::string key, std::string label, const ViRun* start) {
  const PoolLimits all{.max_landmarks = std::numeric_limits<std::size_t>::max() / 2,
                       .max_new_per_step = std::numeric_limits<std::size_t>::max() / 2};
  ViRun out = run_backend(graph, d, all, 0, std::move(key), std::move(label));
  const auto started = std::chrono::steady_clock::now();
  if (start) warm_start_from(graph, *start);
  const auto summary = graph.optimize();
  out.seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  out.means.assign(graph.pose_means().begin() + 1, graph.pose_means().end());
  out.map.clear();
  for (const auto& [id, mean] : graph.landmark_means()) out.map.push_back({id, mean, Eigen::Matrix3d::Zero()});
  out.label += ", LM, " + std::to_string(summary.iterations) + " iterations";
  out.optimization = optimization_row(summary);
  return out;
}

ViRun dead_reckoning_row(const ViData& d) {
  ViRun out;
  out.key = "dead_reckoning";
  out.label = "dead reckoning (IMU only)";
  const auto started = std::chrono::steady_clock::now();
  out.means = eval::dead_reckoning(d.motion, d.prior.mean, d.frames);
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return out;
}

/// The key of GraphSLAM's row that starts from the EKF's estimate (vislam_choices, run_all).
constexpr const char* kGraphFromEkf = "graph_from_ekf";

/// The back-end configurations: the filters with the [vislam] gate, the EKF also with first-estimate
/// Jacobians; GraphSLAM with Levenberg-Marquardt and a Huber loss at the gate's quantile (run_graph),
/// and where the EKF runs too, GraphSLAM again from the EKF's estimate (docs/results/vislam.md: on
/// 0027_noisy.npz dead reckoning's start ends in a local optimum).
std::vector<BackendChoice> vislam_choices(const std::vector<BackendKind>& kinds, const RunnerConfig& c) {
  std::vector<BackendChoice> choices;
  for (auto choice : backend_choices<Motion>(kinds, c)) {
    choice.ekf.gate_probability = choice.seif.gate_probability = choice.fastslam.gate_probability =
        c.vislam.gate_probability;
    choice.graph.levenberg_marquardt = true;
    if (c.vislam.gate_probability > 0.0)
      choice.graph.measurement_loss = {RobustKernel::huber, std::sqrt(chi_square_quantile(4, c.vislam.gate_probability))};
    choices.push_back(choice);
    if (choice.kind != BackendKind::ekf) continue;
    choice.ekf.first_estimate_jacobians = true;
    choice.key = "ekf_fej";
    choice.label = "EKF-SLAM, first-estimate Jacobians";
    choices.push_back(std::move(choice));
  }
  // Last, after the EKF it starts from (run_all).
  const bool with_ekf = std::ranges::any_of(choices, [](const BackendChoice& b) { return b.key == "ekf"; });
  const auto graph = std::ranges::find(choices, BackendKind::graph, &BackendChoice::kind);
  if (with_ekf && graph != choices.end()) {
    auto from_ekf = *graph;
    from_ekf.key = kGraphFromEkf;
    from_ekf.label = "GraphSLAM from EKF";  // + ", LM, 100 iterations": the table's 38 characters
    choices.push_back(std::move(from_ekf));
  }
  return choices;
}

std::vector<ViRun> run_all(const ViData& d, const std::vector<BackendKind>& kinds, const RunnerConfig& c) {
  std::vector<ViRun> runs{dead_reckoning_row(d)};
  for (const auto& choice : vislam_choices(kinds, c)) {
    const ViRun* start = nullptr;  // into runs: run_graph has returned before runs grows
    if (choice.key == kGraphFromEkf) {
      const auto ekf = std::ranges::find(runs, std::string("ekf"), &ViRun::key);
      if (ekf == runs.end() || ekf->failure) continue;  // no EKF estimate to start from: no row
      start = &*ekf;
    }
    const auto failure = failure_of([&] {
      with_backend(choice, d.motion, d.sensor, d.prior, [&](auto& backend) {
        if constexpr (requires { backend.optimize(); })
          runs.push_back(run_graph(backend, d, choice.key, choice.label, start));
        else  // the EKF's pose covariance after every frame, the others' every 10th (a SEIF's costs a factorization)
          runs.push_back(run_backend(backend, d, c.vislam.pool, choice.kind == BackendKind::ekf ? 1 : 10, choice.key,
                                     choice.label));
      });
    });
    if (failure) runs.push_back(failed_run<ViRun>(choice, *failure));  // its row says so; the others still run
  }
  return runs;
}

double trajectory_length(const std::vector<Eigen::Matrix4d>& poses) {
  double length = 0.0;
  for (std::size_t k = 1; k < poses.size(); ++k) length += (se3::translation(poses[k]) - se3::translation(poses[k - 1])).norm();
  return length;
}

/// Position RMSE against the reference, and with the truth the pose ANEES (6 dof, world-frame error).
void score(ViRun& r, const ViData& d) {
  if (d.reference.empty() || r.failure) return;
  double squared = 0.0;
  for (std::size_t k = 0; k < r.means.size(); ++k)
    squared += (se3::translation(r.means[k]) - se3::translation(d.reference[k])).squaredNorm();
  r.rmse = std::sqrt(squared / static_cast<double>(r.means.size()));
  if (!d.reference_is_truth || r.poses.empty()) return;
  r.anees = eval::sampled_pose_anees<Se3Space>(r.poses, d.reference);
}

std::string number_or_dash(double value, const char* format) {
  if (std::isnan(value)) return "-";
  char text[32];
  std::snprintf(text, sizeof text, format, value);
  return text;
}

void print_table(const ViData& d, const std::vector<ViRun>& runs) {
  const double dead_reckoning_rmse = runs.front().rmse;
  std::printf("%-38s %9s %8s %8s %9s %7s %8s %9s %8s %9s %9s\n", "back-end", "length[m]", "in state", "mapped",
              "corrected", "gated", "unusable", "RMSE [m]", "vs DR", "pose ANEES", "ms/frame");
  for (const auto& r : runs) {
    if (r.failure) {
      std::printf("%-38s failed: %s\n", r.label.c_str(), r.failure->c_str());
      continue;
    }
    std::printf("%-38s %9.1f %8zu %8zu %9zu %7zu %8zu %9s %8s %9s %9.2f\n", r.label.c_str(), trajectory_length(r.means),
                r.in_state, r.updates.initialized, r.updates.corrected, r.updates.rejected, r.updates.unusable, number_or_dash(r.rmse, "%.2f").c_str(),
                number_or_dash(dead_reckoning_rmse / r.rmse, "%.2fx").c_str(), number_or_dash(r.anees, "%.2f").c_str(),
                1e3 * r.seconds / static_cast<double>(d.frames.size()));
    if (r.optimization) print_optimization(38, *r.optimization);
    print_skipped_steps(38, r.failures.total(), "frame", r.failures.first);
  }
  std::printf("RMSE: position against %s; vs DR: dead reckoning's RMSE over this one (higher is better); in state: "
              "landmarks in the state at the end (pool of at most that many); mapped: landmarks added; unusable: "
              "observations behind or too near the camera, outside its field of view, or below the smallest "
              "disparity for a new landmark; pose ANEES: 6 dof, 95%% of single "
              "steps below 12.59.\n",
              d.reference.empty() ? "nothing (no reference beside the file)" : d.reference_label.c_str());
}

TableRow table_row(const ViData& d, const ViRun& r) {
  eval::Summary s;
  s.mark_unscored();
  s.pose_rmse = r.rmse;
  s.pose_anees = r.anees;
  s.total_seconds = r.seconds;
  s.seconds_per_step = r.seconds / static_cast<double>(d.frames.size());
  s.failed_steps = r.failures.total();
  s.first_failure = r.failures.first;
  TableRow row{.dataset = d.name, .backend = r.key, .label = r.label, .summary = s, .optimization = r.optimization};
  row.failure = r.failure;
  return row;
}

void write_outputs(const RunOptions& options, const ViData& d, const std::vector<ViRun>& runs, const RunnerConfig& c) {
  if (options.out.empty()) return;
  const auto dir = std::filesystem::path(options.out) / std::filesystem::path(d.name).stem();
  std::filesystem::create_directories(dir);
  auto tum = [&](const std::vector<Eigen::Matrix4d>& poses) {
    std::vector<io::TumPose> out;
    for (std::size_t k = 0; k < poses.size(); ++k)
      out.push_back({d.times[k], se3::translation(poses[k]), Eigen::Quaterniond(se3::rotation(poses[k]))});
    return out;
  };
  if (!d.reference.empty()) io::write_tum((dir / "reference.tum").string(), tum(d.reference));
  for (const auto& r : runs) {
    if (r.failure) continue;
    io::write_tum((dir / (r.key + "_trajectory.tum")).string(), tum(r.means));
    if (r.map.empty()) continue;
    io::CsvWriter csv((dir / (r.key + "_map.csv")).string(), {"id", "x", "y", "z"});
    for (const auto& l : r.map) csv.row({static_cast<double>(l.id), l.mean.x(), l.mean.y(), l.mean.z()});
    mrpt_io::SceneContent scene;
    for (const auto& T : r.means) scene.estimated_path.push_back(se3::translation(T));
    for (const auto& T : d.reference) scene.true_path.push_back(se3::translation(T));
    scene.landmarks = mrpt_io::scene_landmarks(r.map);
    for (auto& l : scene.landmarks) l.planar = false;
    for (const auto& [id, p] : d.true_landmarks) scene.true_landmarks.push_back(p);
    mrpt_io::write_scene((dir / (r.key + ".3Dscene")).string(), scene, {.quantile = c.scene_quantile});
  }
  std::printf("wrote TUM trajectories, landmark maps (CSV) and .3Dscene files to %s\n", dir.c_str());
  if (options.plots) run_plot_script("plot_vislam.py", dir);
}

/// Visual-inertial SLAM on "stereo-vi" (the simulator) or a KITTI-derived .npz file.
std::vector<TableRow> run_vislam(const CliOptions& cli, const std::string& dataset, const std::vector<BackendKind>& kinds,
                                 const RunnerConfig& config) {
  const ViData d = dataset == "stereo-vi" ? simulated(config) : from_npz(dataset, config);
  std::printf("\n== %s: visual-inertial SLAM on SE(3) (seed 004), %zu frames, pool of %zu landmarks (%zu new per "
              "frame), pixel sigma %.2f px, smallest disparity for a new landmark %.1f px\n",
              d.name.c_str(), d.frames.size(), config.vislam.pool.max_landmarks, config.vislam.pool.max_new_per_step,
              d.sensor.pixel_sigma, d.sensor.min_disparity);
  auto runs = run_all(d, kinds, config);
  for (auto& r : runs) score(r, d);
  print_table(d, runs);
  std::vector<TableRow> rows;
  for (const auto& r : runs) rows.push_back(table_row(d, r));
  write_outputs(cli.output, d, runs, config);
  return rows;
}

const RegisterDatasetRun simulated_registration{"stereo-vi", run_vislam};
const RegisterDatasetRun npz_registration{"npz", run_vislam};

}  // namespace
}  // namespace sextant::runner
