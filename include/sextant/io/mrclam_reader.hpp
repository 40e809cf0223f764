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
#include <map>
#include <set>
#include <string>
#include <vector>

#include "sextant/core/error.hpp"
#include "sextant/core/observation.hpp"
#include "sextant/core/state_space.hpp"
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
  MrclamCounts counts;
};

namespace detail {

struct TimedRow {
  double t;
  std::vector<double> values;
  int line;
};

/// Rows of `columns` values with a time in the first, in non-decreasing time order.
inline std::vector<TimedRow> read_timed_rows(const std::string& path, std::size_t columns, const char* layout) {
  std::vector<TimedRow> out;
  for (auto& [line, values] : read_numeric_rows(path)) {
    const std::string where = path + ":" + std::to_string(line);
    if (values.size() != columns)
      throw parse_error(where + ": expected " + std::to_string(columns) + " values (" + layout + "), got " +
                        std::to_string(values.size()));
    if (!out.empty() && values[0] < out.back().t)
      throw parse_error(where + ": time " + std::to_string(values[0]) + " is before the previous row's");
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

/// Reads robot `robot` (1-based) of the MRCLAM data set in `directory`.
inline MrclamRun read_mrclam(const std::string& directory, int robot, const MrclamOptions& options = {}) {
  if (!(options.max_step > 0.0) || !std::isfinite(options.max_step))
    throw invalid_input_error("MRCLAM: max_step must be a positive number of seconds");
  if (!(options.measurement_sigma.array() > 0.0).all() || !(options.prior_sigma.array() > 0.0).all() ||
      !options.measurement_sigma.allFinite() || !options.prior_sigma.allFinite())
    throw invalid_input_error("MRCLAM: measurement and prior standard deviations must be positive and finite");
  const std::filesystem::path dir(directory);
  const std::string prefix = "Robot" + std::to_string(robot) + "_";
  const auto file = [&](const std::string& name) { return (dir / name).string(); };
  if (!std::filesystem::exists(file(prefix + "Odometry.dat")))
    throw parse_error(file(prefix + "Odometry.dat") + ": cannot open file (robot " + std::to_string(robot) +
                      " of an MRCLAM data set?)");

  std::map<LandmarkId, LandmarkId> subject_of_barcode;
  for (const auto& [line, values] : detail::read_numeric_rows(file("Barcodes.dat"))) {
    const std::string where = file("Barcodes.dat") + ":" + std::to_string(line);
    if (values.size() != 2) throw parse_error(where + ": expected 2 values (subject barcode)");
    if (!subject_of_barcode.emplace(detail::subject_id(values[1], where), detail::subject_id(values[0], where)).second)
      throw parse_error(where + ": barcode listed twice");
  }
  MrclamRun run;
  run.path = directory + " robot " + std::to_string(robot);
  run.motion = options.motion;
  run.sensor.Q = options.measurement_sigma.cwiseAbs2().asDiagonal();
  for (const auto& [line, values] : detail::read_numeric_rows(file("Landmark_Groundtruth.dat"))) {
    const std::string where = file("Landmark_Groundtruth.dat") + ":" + std::to_string(line);
    if (values.size() != 5) throw parse_error(where + ": expected 5 values (subject x y sx sy)");
    if (!run.true_landmarks.emplace(detail::subject_id(values[0], where), Eigen::Vector2d(values[1], values[2])).second)
      throw parse_error(where + ": landmark listed twice");
  }
  auto odometry = detail::read_timed_rows(file(prefix + "Odometry.dat"), 3, "t v w");
  for (auto& row : odometry) row.t += options.odometry_delay;
  const auto truth = detail::read_timed_rows(file(prefix + "Groundtruth.dat"), 4, "t x y heading");
  const auto measurements = detail::read_timed_rows(file(prefix + "Measurement.dat"), 4, "t barcode range bearing");

  const double start = std::max(odometry.front().t, truth.front().t);
  const double end = std::min(odometry.back().t, truth.back().t);
  if (!(end > start)) throw parse_error(run.path + ": odometry and ground truth do not overlap in time");
  run.start_time = start;
  run.prior.mean = detail::interpolate_pose(truth, start);
  run.prior.cov = options.prior_sigma.cwiseAbs2().asDiagonal();
  run.true_poses.push_back(run.prior.mean);
  run.counts.odometry_samples = odometry.size();

  // Step ends: every measurement time inside the run, then filled so no step exceeds max_step.
  std::vector<double> ends;
  for (const auto& row : measurements)
    if (row.t > start && row.t <= end && (ends.empty() || row.t > ends.back())) ends.push_back(row.t);
  if (ends.empty() || ends.back() < end) ends.push_back(end);
  std::size_t next = 1;
  while (next < odometry.size() && odometry[next].t <= start) ++next;
  std::size_t measurement = 0;
  double t = start;
  for (const double stop : ends) {
    const int pieces = std::max(1, static_cast<int>(std::ceil((stop - t) / options.max_step - 1e-9)));
    const double length = (stop - t) / pieces;
    for (int piece = 1; piece <= pieces; ++piece) {
      const double b = piece == pieces ? stop : t + length;
      run.steps.push_back({detail::mean_velocity(odometry, next, t, b), b - t, {}});
      run.step_times.push_back(b - start);
      t = b;
      run.true_poses.push_back(detail::interpolate_pose(truth, b));
    }
    std::set<LandmarkId> seen;
    for (; measurement < measurements.size() && measurements[measurement].t <= stop; ++measurement) {
      const auto& row = measurements[measurement];
      const std::string where = file(prefix + "Measurement.dat") + ":" + std::to_string(row.line);
      if (row.t <= start) {
        ++run.counts.outside_run;
        continue;
      }
      const auto barcode = subject_of_barcode.find(detail::subject_id(row.values[1], where));
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
        run.steps.back().observations.push_back({barcode->second, Eigen::Vector2d(row.values[2], row.values[3])});
        ++run.counts.measurements;
      }
    }
  }
  run.counts.outside_run += measurements.size() - measurement;
  return run;
}

}  // namespace sextant::io
