#pragma once
/// \file Reader for one robot of a UTIAS MRCLAM data set (Leung et al., IJRR 2011): a directory
/// with Barcodes.dat (subject, barcode), Landmark_Groundtruth.dat (subject, x, y, sx, sy),
/// RobotN_Odometry.dat (t, v, w), RobotN_Measurement.dat (t, barcode, range, bearing) and
/// RobotN_Groundtruth.dat (t, x, y, heading; Vicon, ~100 Hz). Plain text, no MRPT needed.
///
/// The run covers the time both odometry and Vicon cover. It is cut into steps that end at every
/// measurement time and are at most `max_step` long; a step's control is the mean of the
/// piecewise-constant odometry (v, w) over it (each sample holds until the next one), so the
/// step's heading change is exact and its arc is the mean arc. Measurements of robots (subjects
/// 1-5) and of barcodes Barcodes.dat does not list are dropped and counted; the landmark id is the
/// subject number. The true pose at the end of each step is Vicon's, interpolated.

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "sextant/core/error.hpp"
#include "sextant/core/observation.hpp"
#include "sextant/core/state_space.hpp"
#include "sextant/io/implausible_values.hpp"
#include "sextant/io/landmark_dataset.hpp"
#include "sextant/io/numeric_rows.hpp"
#include "sextant/io/parse_number.hpp"
#include "sextant/models/range_bearing_2d.hpp"
#include "sextant/models/unicycle.hpp"

namespace sextant::io {

/// How the run is cut into steps and the models it is run with. The noise defaults were read off
/// Dataset6 against Vicon (docs/results/mrclam.md): robust standard deviations of the range and
/// bearing residuals 0.13 m and 0.0086 rad; the odometry's error over 1 s windows, scaled to
/// 0.25 s steps and widened to cover its bias (about 5% of the distance driven).
struct MrclamOptions {
  double max_step = 0.25;  ///< [s] longest step without a measurement
  int robot_subjects = 5;  ///< subjects 1..robot_subjects are robots; their sightings are dropped
  Unicycle motion{.alpha = {0.015, 0.002, 0.02, 0.1, 0.0, 0.001}, .floor_rate = Eigen::Vector3d(4e-6, 4e-6, 1e-5)};
  Eigen::Vector2d measurement_sigma = Eigen::Vector2d(0.15, 0.02);  ///< (range [m], bearing [rad])
  Eigen::Vector3d prior_sigma = Eigen::Vector3d(0.01, 0.01, 0.01);  ///< of the initial pose (Vicon's)
  /// [s] added to every odometry time stamp: the robot moves as commanded this long after the
  /// stamp (Dataset6: odometry w best matches Vicon's yaw rate 0.2 s later, docs/results/mrclam.md).
  double odometry_delay = 0.0;
  /// [s] the longest gap allowed between two odometry or two Vicon rows (Dataset6: at most 1.03 and
  /// 2.03 s; landmark measurements may pause for minutes). A longer one is an error naming the row:
  /// the steps across it would have no control, and a stray time stamp would cut the run into
  /// millions of steps.
  double max_gap = 60.0;
  /// The most steps a run may be cut into (10^6 steps of 0.25 s are 69 hours; Dataset6's robots
  /// have 3293-4212 with the defaults); more is an error before any step is made.
  std::size_t max_steps = 1'000'000;
  /// Beyond these a value is used but listed as implausible (MrclamRun::implausible): |v| in m/s
  /// (Dataset6's largest 0.086; an iRobot Create drives at most 0.5), |w| in rad/s (largest 0.57),
  /// a range in m (largest 8.6).
  double plausible_speed = 2.0, plausible_rate = 6.283185307179586, plausible_range = 30.0;
};

struct MrclamCounts {
  std::size_t odometry_samples = 0;
  std::size_t measurements = 0;      ///< landmark measurements in the run
  std::size_t robot_sightings = 0;   ///< dropped: measurements of another robot
  std::size_t unknown_barcodes = 0;  ///< dropped: a barcode Barcodes.dat does not list
  std::size_t outside_run = 0;       ///< dropped: before the first or after the last step
  std::size_t repeated_in_step = 0;  ///< dropped: a landmark measured twice at one time (the first is kept)
};

/// One robot's run: steps of (v, w) controls and (range, bearing) observations with the subject as
/// landmark id; true_poses[k + 1] is Vicon after step k.
struct MrclamRun : LandmarkDataset<Unicycle, RangeBearing2D> {
  double start_time = 0.0;          ///< absolute time [s] of the initial pose
  std::vector<double> step_times;   ///< [s] end of each step, from start_time
  MrclamCounts counts;  ///< (`implausible`: velocities and ranges beyond MrclamOptions' plausible limits)
};

namespace detail {

struct TimedRow {
  double t;
  std::vector<double> values;
  int line;
};

/// Rows of `columns` values with a time in the first, in non-decreasing time order.
/// The rows of a file of time-stamped rows, times non-decreasing and (max_gap) no two rows further
/// apart than max_gap seconds.
inline std::vector<TimedRow> read_timed_rows(const std::string& path, std::size_t columns, const char* layout,
                                             double max_gap = std::numeric_limits<double>::infinity()) {
  std::vector<TimedRow> out;
  for (auto& [line, values] : read_numeric_rows(path)) {
    const std::string where = path + ":" + std::to_string(line);
    if (values.size() != columns)
      throw parse_error(where + ": expected " + std::to_string(columns) + " values (" + layout + "), got " +
                        std::to_string(values.size()));
    if (!out.empty() && values[0] < out.back().t)
      throw parse_error(where + ": time " + std::to_string(values[0]) + " is before the previous row's");
    if (!out.empty() && values[0] - out.back().t > max_gap)
      throw parse_error(where + ": " + std::to_string(values[0] - out.back().t) + " s after the previous row, more than " +
                        std::to_string(max_gap) + " s (MrclamOptions::max_gap)");
    out.push_back({values[0], std::move(values), line});
  }
  if (out.empty()) throw parse_error(path + ": no data rows");
  return out;
}

inline LandmarkId subject_id(double value, const std::string& where) {
  const auto id = as_identifier(value);
  if (!id) throw parse_error(where + ": subject and barcode numbers must be non-negative integers");
  return *id;
}

/// Vicon pose at time t by linear interpolation (heading along the shorter arc).
inline Eigen::Vector3d interpolate_pose(const std::vector<TimedRow>& truth, double t) {
  auto after = std::lower_bound(truth.begin(), truth.end(), t, [](const TimedRow& row, double v) { return row.t < v; });
  if (after == truth.begin()) after = std::next(after);
  if (after == truth.end()) after = std::prev(after);
  const auto& b = *after;
  const auto& a = *std::prev(after);
  const double span = b.t - a.t, f = span > 0.0 ? std::clamp((t - a.t) / span, 0.0, 1.0) : 1.0;
  const Eigen::Vector3d pa(a.values[1], a.values[2], a.values[3]), pb(b.values[1], b.values[2], b.values[3]);
  Eigen::Vector3d out = pa + f * (pb - pa);
  out(2) = wrap_angle(pa(2) + f * wrap_angle(pb(2) - pa(2)));
  return out;
}

/// Mean of the piecewise-constant odometry over [a, b]; `next` is the index of the first sample
/// after a, advanced to the first sample after b.
inline UnicycleControl mean_velocity(const std::vector<TimedRow>& odometry, std::size_t& next, double a, double b) {
  double v = 0.0, w = 0.0, t = a;
  while (t < b) {
    const double held_until = next < odometry.size() ? std::min(odometry[next].t, b) : b;
    const auto& sample = odometry[next - 1];
    v += sample.values[1] * (held_until - t);
    w += sample.values[2] * (held_until - t);
    t = held_until;
    if (next < odometry.size() && odometry[next].t <= b) ++next;
  }
  return {v / (b - a), w / (b - a)};
}

}  // namespace detail

namespace detail {

inline void require_valid(const MrclamOptions& options) {
  if (!(options.max_step > 0.0) || !std::isfinite(options.max_step))
    throw invalid_input_error("MRCLAM: max_step must be a positive number of seconds");
  if (!(options.measurement_sigma.array() > 0.0).all() || !(options.prior_sigma.array() > 0.0).all() ||
      !options.measurement_sigma.allFinite() || !options.prior_sigma.allFinite())
    throw invalid_input_error("MRCLAM: measurement and prior standard deviations must be positive and finite");
  if (!(options.max_gap > 0.0)) throw invalid_input_error("MRCLAM: max_gap must be a positive number of seconds");
}

/// Barcodes.dat: subject of each barcode.
inline std::map<LandmarkId, LandmarkId> read_barcodes(const std::string& path) {
  std::map<LandmarkId, LandmarkId> subject_of_barcode;
  for (const auto& [line, values] : read_numeric_rows(path)) {
    const std::string where = path + ":" + std::to_string(line);
    if (values.size() != 2) throw parse_error(where + ": expected 2 values (subject barcode)");
    if (!subject_of_barcode.emplace(subject_id(values[1], where), subject_id(values[0], where)).second)
      throw parse_error(where + ": barcode listed twice");
  }
  return subject_of_barcode;
}

/// Landmark_Groundtruth.dat: each landmark subject's position.
inline std::map<LandmarkId, Eigen::Vector2d> read_landmarks(const std::string& path) {
  std::map<LandmarkId, Eigen::Vector2d> landmarks;
  for (const auto& [line, values] : read_numeric_rows(path)) {
    const std::string where = path + ":" + std::to_string(line);
    if (values.size() != 5) throw parse_error(where + ": expected 5 values (subject x y sx sy)");
    if (!landmarks.emplace(subject_id(values[0], where), Eigen::Vector2d(values[1], values[2])).second)
      throw parse_error(where + ": landmark listed twice");
  }
  return landmarks;
}

/// Where the steps end: at every measurement time inside (start, end], then split so that no step
/// is longer than max_step. Throws before making them when they would be more than max_steps.
inline std::vector<double> step_ends(const std::vector<TimedRow>& measurements, double start, double end,
                                     const MrclamOptions& options, const std::string& run) {
  std::vector<double> stops;
  for (const auto& row : measurements)
    if (row.t > start && row.t <= end && (stops.empty() || row.t > stops.back())) stops.push_back(row.t);
  if (stops.empty() || stops.back() < end) stops.push_back(end);
  double count = 0.0, t = start;
  for (const double stop : stops) count += std::max(1.0, std::ceil((stop - t) / options.max_step - 1e-9)), t = stop;
  if (count > static_cast<double>(options.max_steps))
    throw parse_error(run + ": " + std::to_string(end - start) + " s cut into steps of at most " +
                      std::to_string(options.max_step) + " s would be " + std::to_string(static_cast<long long>(count)) +
                      " steps, more than " + std::to_string(options.max_steps) + " (MrclamOptions::max_steps)");
  std::vector<double> ends;
  t = start;
  for (const double stop : stops) {
    const int pieces = std::max(1, static_cast<int>(std::ceil((stop - t) / options.max_step - 1e-9)));
    const double length = (stop - t) / pieces;
    for (int piece = 1; piece <= pieces; ++piece) ends.push_back(piece == pieces ? stop : t + length), t = ends.back();
  }
  return ends;
}

/// The measurements up to time `stop` (from `next` on) into the last step: landmark sightings
/// become observations; the others are counted (before the run, unknown barcodes, other robots,
/// a landmark twice at one time).
inline void add_measurements(MrclamRun& run, const std::vector<TimedRow>& measurements, std::size_t& next,
                             const std::map<LandmarkId, LandmarkId>& subject_of_barcode, double start, double stop,
                             const MrclamOptions& options, const std::string& path) {
  std::set<LandmarkId> seen;
  for (; next < measurements.size() && measurements[next].t <= stop; ++next) {
    const auto& row = measurements[next];
    const std::string where = path + ":" + std::to_string(row.line);
    if (row.t <= start) {
      ++run.counts.outside_run;
      continue;
    }
    const auto barcode = subject_of_barcode.find(subject_id(row.values[1], where));
    if (barcode == subject_of_barcode.end()) {
      ++run.counts.unknown_barcodes;
    } else if (barcode->second <= static_cast<LandmarkId>(options.robot_subjects)) {
      ++run.counts.robot_sightings;
    } else if (!run.true_landmarks.contains(barcode->second)) {
      ++run.counts.unknown_barcodes;
    } else if (!seen.insert(barcode->second).second) {
      ++run.counts.repeated_in_step;
    } else {
      if (!(row.values[2] > 0.0)) throw parse_error(where + ": range must be positive");
      run.implausible.check(row.values[2], options.plausible_range, where, "range", "m");
      run.steps.back().observations.push_back({barcode->second, Eigen::Vector2d(row.values[2], row.values[3])});
      ++run.counts.measurements;
    }
  }
}

}  // namespace detail

/// Reads robot `robot` (1-based) of the MRCLAM data set in `directory`.
inline MrclamRun read_mrclam(const std::string& directory, int robot, const MrclamOptions& options = {}) {
  detail::require_valid(options);
  const std::filesystem::path dir(directory);
  const std::string prefix = "Robot" + std::to_string(robot) + "_";
  const auto file = [&](const std::string& name) { return (dir / name).string(); };
  if (!std::filesystem::is_regular_file(file(prefix + "Odometry.dat")))
    throw parse_error(file(prefix + "Odometry.dat") + ": cannot open file (robot " + std::to_string(robot) +
                      " of an MRCLAM data set?)");
  const auto subject_of_barcode = detail::read_barcodes(file("Barcodes.dat"));
  MrclamRun run;
  run.path = directory + " robot " + std::to_string(robot);
  run.motion = options.motion;
  run.sensor.Q = options.measurement_sigma.cwiseAbs2().asDiagonal();
  for (const auto& [subject, position] : detail::read_landmarks(file("Landmark_Groundtruth.dat")))
    run.true_landmarks.emplace(subject, position);
  auto odometry = detail::read_timed_rows(file(prefix + "Odometry.dat"), 3, "t v w", options.max_gap);
  for (auto& row : odometry) {
    row.t += options.odometry_delay;
    const std::string where = file(prefix + "Odometry.dat") + ":" + std::to_string(row.line);
    run.implausible.check(row.values[1], options.plausible_speed, where, "speed", "m/s");
    run.implausible.check(row.values[2], options.plausible_rate, where, "turn rate", "rad/s");
  }
  const auto truth = detail::read_timed_rows(file(prefix + "Groundtruth.dat"), 4, "t x y heading", options.max_gap);
  const auto measurements = detail::read_timed_rows(file(prefix + "Measurement.dat"), 4, "t barcode range bearing");

  const double start = std::max(odometry.front().t, truth.front().t);
  const double end = std::min(odometry.back().t, truth.back().t);
  if (!(end > start)) throw parse_error(run.path + ": odometry and ground truth do not overlap in time");
  run.start_time = start;
  run.prior.mean = detail::interpolate_pose(truth, start);
  run.prior.cov = options.prior_sigma.cwiseAbs2().asDiagonal();
  run.true_poses.push_back(run.prior.mean);
  run.counts.odometry_samples = odometry.size();
  std::size_t next = 1;
  while (next < odometry.size() && odometry[next].t <= start) ++next;
  std::size_t measurement = 0;
  double t = start;
  for (const double b : detail::step_ends(measurements, start, end, options, run.path)) {
    run.steps.push_back({detail::mean_velocity(odometry, next, t, b), b - t, {}});
    run.step_times.push_back(b - start);
    run.true_poses.push_back(detail::interpolate_pose(truth, b));
    t = b;
    detail::add_measurements(run, measurements, measurement, subject_of_barcode, start, b, options,
                             file(prefix + "Measurement.dat"));
  }
  run.counts.outside_run += measurements.size() - measurement;
  if (run.counts.measurements == 0)
    throw parse_error(run.path + ": no landmark measurement inside the odometry and Vicon time span (" +
                      std::to_string(run.counts.outside_run) + " outside it, " +
                      std::to_string(run.counts.unknown_barcodes) + " of unknown barcodes, " +
                      std::to_string(run.counts.robot_sightings) + " of robots)");
  return run;
}

}  // namespace sextant::io
