// sextant-run's MRCLAM part: every chosen back-end on one or all robots of a UTIAS MRCLAM data set
// (--dataset mrclam:<dir>:<robot|all>), scored against Vicon, beside dead reckoning.
#include <Eigen/Geometry>
#include <cmath>
#include <sextant/eval/alignment.hpp>
#include <sextant/eval/dead_reckoning.hpp>
#include <sextant/eval/metrics.hpp>
#include <sextant/io/mrclam_reader.hpp>

#include "dataset_registry.hpp"
#include "dataset_runner.hpp"
#include "planar_world_frame_runs.hpp"

namespace sextant::runner {

namespace {

/// Dead reckoning against Vicon, and the part of its error no back-end can remove.
struct DeadReckoningScore {
  double rmse = 0.0;                ///< of the controls integrated from the start pose
  double aligned_rmse = 0.0;        ///< the same after the best rigid alignment to Vicon
  double first_sighting_time = 0.0;   ///< [s] of the first landmark measurement
  double heading_error = 0.0;       ///< [rad] dead reckoning's at that time
  /// Until the first sighting only the start pose and the odometry say where the robot is; the map
  /// is built from the pose then, so dead reckoning's error there (the heading above all) is
  /// unobservable and stays in every estimate. This is the RMSE of a back-end exact relative to that
  /// pose: dead reckoning before it, the true trajectory moved rigidly by that error after it.
  double floor_rmse = 0.0;
};

DeadReckoningScore score_dead_reckoning(const io::MrclamRun& data) {
  const auto x = eval::dead_reckoning(data.motion, data.prior.mean, data.steps);
  DeadReckoningScore out;
  if (x.empty()) return out;
  std::size_t first = 0;
  while (first + 1 < data.steps.size() && data.steps[first].observations.empty())
    out.first_sighting_time += data.steps[first++].dt;
  out.first_sighting_time += data.steps[first].dt;
  const Eigen::Vector3d& truth_then = data.true_poses[first + 1];
  out.heading_error = wrap_angle(x[first](2) - truth_then(2));
  const Eigen::Rotation2Dd turn(out.heading_error);
  double sum = 0.0, floor_sum = 0.0;
  std::vector<Eigen::Vector2d> positions, true_positions;
  for (std::size_t k = 0; k < x.size(); ++k) {
    const Eigen::Vector2d truth = data.true_poses[k + 1].head<2>();
    positions.push_back(x[k].head<2>());
    true_positions.push_back(truth);
    sum += (x[k].head<2>() - truth).squaredNorm();
    const Eigen::Vector2d exact_after = x[first].head<2>() + turn * (truth - truth_then.head<2>());
    floor_sum += ((k < first ? x[k].head<2>() : exact_after) - truth).squaredNorm();
  }
  out.rmse = std::sqrt(sum / static_cast<double>(x.size()));
  out.floor_rmse = std::sqrt(floor_sum / static_cast<double>(x.size()));
  out.aligned_rmse = eval::rms(eval::aligned_errors<2>(positions, true_positions));
  return out;
}

/// The EKF row's filter given the surveyed map: every landmark put into it at its surveyed position
/// with a 1 mm standard deviation before the first step (EkfSlam::add_landmark), otherwise as the
/// row. A filter estimates each pose from the past alone, so one that must also build the map has
/// less to go on than this; a smoother (GraphSLAM) uses the sightings after a pose too.
template <class Dataset>
eval::RunScores score_filter_given_map(const Dataset& data, const RunnerConfig& config) {
  constexpr Scoring scoring = scoring_of<Dataset>();
  const auto choice = backend_choices<typename Dataset::Motion>({BackendKind::ekf}, config).front();
  EkfSlam<typename Dataset::Motion, typename Dataset::Sensor> ekf(data.motion, data.sensor, data.prior, choice.ekf);
  for (const auto& [id, m] : data.true_landmarks) ekf.add_landmark({id, m, 1e-6 * Eigen::Matrix2d::Identity()});
  const auto run = eval::evaluate_run(ekf, data, scoring.position_dim, eval::NoStepCallback{}, eval::StepErrors::skip);
  return eval::scores_of(run, scoring.pose_dof, scoring.landmark_dof);
}

/// The config with the [mrclam] gate, re-acquisition and kernel set on the back-ends
/// (RunnerConfig::mrclam_gate_probability); re-acquisition needs the gate. FastSLAM keeps its own
/// [fastslam] gate (off by default): its cloud's predictive covariance is overconfident on this data
/// and a gate on it rejects the sightings that would bring a drifted cloud back (docs/results/mrclam.md).
RunnerConfig with_mrclam_robustness(RunnerConfig c) {
  c.ekf.gate_probability = c.seif.gate_probability = c.mrclam_gate_probability;
  c.ekf.reacquisition.min_landmarks = c.seif.reacquisition.min_landmarks =
      c.mrclam_gate_probability > 0.0 ? c.mrclam_reacquire_after_landmarks : 0;
  c.graph.measurement_loss.kernel = c.mrclam_graph_kernel;
  return c;
}

/// "<dir>:<robot>" with robot 1..5 or "all".
std::pair<std::string, std::vector<int>> parse_spec(const std::string& spec) {
  const auto colon = spec.rfind(':');
  if (colon == std::string::npos || colon == 0)
    throw invalid_input_error("--dataset mrclam:" + spec + ": expected mrclam:<directory>:<robot 1-5 or all>");
  const std::string directory = spec.substr(0, colon), robot = spec.substr(colon + 1);
  if (robot == "all") return {directory, {1, 2, 3, 4, 5}};
  if (robot.size() == 1 && robot[0] >= '1' && robot[0] <= '9') return {directory, {robot[0] - '0'}};
  throw invalid_input_error("--dataset mrclam:" + spec + ": robot must be a number 1-9 or all, got '" + robot + "'");
}

std::vector<TableRow> run_mrclam(const CliOptions& cli, const std::string& dataset, const std::vector<BackendKind>& kinds,
                                 const RunnerConfig& settings) {
  const RunnerConfig config = with_mrclam_robustness(settings);
  const RunOptions& options = cli.output;
  const auto [directory, robots] = parse_spec(dataset.substr(std::string("mrclam:").size()));
  std::vector<TableRow> rows;
  for (const int robot : robots) {
    const auto data = io::read_mrclam(directory, robot, config.mrclam);
    const std::string name =
        std::filesystem::path(directory).filename().string() + "_robot" + std::to_string(robot);
    const auto& c = data.counts;
    std::printf("\n%s: %zu landmark measurements used; dropped %zu sightings of robots, %zu unknown barcodes, %zu outside "
                "the Vicon/odometry time span, %zu repeated at one time\n",
                name.c_str(), c.measurements, c.robot_sightings, c.unknown_barcodes, c.outside_run, c.repeated_in_step);
    print_warnings(data.implausible);
    print_dataset_header(name, data, "m");
    const auto part =
        run_rows_with_filters_in_world_frame(options, name, data, kinds, config, config.mrclam_filters_in_world_frame, "m");
    const auto drift = score_dead_reckoning(data);
    std::printf("dead reckoning at the first sighting (%.1f s): heading off by %.3f rad, which no back-end can see; "
                "a back-end exact from then on has position RMSE %.3f m\n",
                drift.first_sighting_time, drift.heading_error, drift.floor_rmse);
    const auto given_map = config.mrclam_filters_in_world_frame ? score_filter_given_map(in_world_frame(data), config)
                                                                 : score_filter_given_map(data, config);
    const std::string failed =
        given_map.failed_steps ? ", " + std::to_string(given_map.failed_steps) + " failed steps" : std::string();
    std::printf("the EKF given the surveyed map (each landmark known to 1 mm, otherwise as its row): position RMSE %.3f m "
                "(aligned %.3f)%s; a filter that must also map has less to go on\n",
                given_map.pose_rmse, given_map.pose_rmse_aligned, failed.c_str());
    std::printf("position RMSE against Vicon [m] (after rigid alignment): dead reckoning %.3f (%.3f)", drift.rmse,
                drift.aligned_rmse);
    for (const auto& row : part)
      if (row.failure)
        std::printf(", %s failed", row.backend.c_str());
      else
        std::printf(", %s %.3f (%.3f)", row.backend.c_str(), row.summary.pose_rmse, row.summary.pose_rmse_aligned);
    std::printf("\n");
    rows.insert(rows.end(), part.begin(), part.end());
  }
  return rows;
}

const RegisterDatasetRun registration{"mrclam", run_mrclam};

}  // namespace
}  // namespace sextant::runner
