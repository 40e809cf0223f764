// sextant-run's MRCLAM part: every chosen back-end on one or all robots of a UTIAS MRCLAM data set
// (--dataset mrclam:<dir>:<robot|all>), scored against Vicon, beside dead reckoning.
#include <cmath>
#include <sextant/eval/dead_reckoning.hpp>
#include <sextant/io/mrclam_reader.hpp>

#include "dataset_runner.hpp"

namespace sextant::runner {

namespace {

/// Root mean square of the position error of the controls integrated from the start pose.
double dead_reckoning_rmse(const io::MrclamRun& data) {
  const auto x = eval::dead_reckoning(data.motion, data.prior.mean, data.steps);
  double sum = 0.0;
  for (std::size_t k = 0; k < x.size(); ++k) sum += (x[k].head<2>() - data.true_poses[k + 1].head<2>()).squaredNorm();
  return std::sqrt(sum / static_cast<double>(data.steps.size()));
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

}  // namespace

std::vector<TableRow> run_mrclam(const RunOptions& options, const std::string& spec, const std::vector<BackendKind>& kinds,
                                 const RunnerConfig& config) {
  const auto [directory, robots] = parse_spec(spec);
  std::vector<TableRow> rows;
  for (const int robot : robots) {
    const auto data = io::read_mrclam(directory, robot, config.mrclam);
    const std::string name =
        std::filesystem::path(directory).filename().string() + "_robot" + std::to_string(robot);
    const auto& c = data.counts;
    std::printf("\n%s: %zu landmark measurements used; dropped %zu sightings of robots, %zu unknown barcodes, %zu outside "
                "the Vicon/odometry time span, %zu repeated at one time\n",
                name.c_str(), c.measurements, c.robot_sightings, c.unknown_barcodes, c.outside_run, c.repeated_in_step);
    auto part = run_dataset(options, name, data, kinds, config, Scoring{2, 3, 2}, "m");
    std::printf("position RMSE against Vicon [m]: dead reckoning %.3f", dead_reckoning_rmse(data));
    for (const auto& row : part) std::printf(", %s %.3f", row.backend.c_str(), row.summary.pose_rmse);
    std::printf("\n");
    rows.insert(rows.end(), part.begin(), part.end());
  }
  return rows;
}

}  // namespace sextant::runner
