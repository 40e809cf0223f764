#pragma once
/// \file MRPT rawlogs in, sextant steps out. Reads a rawlog (gzip or plain) in either of MRPT's
/// layouts and turns it into a stream of Step<odometry increment, range-bearing measurement>:
///  - action / sensory-frame rawlogs: each CActionCollection followed by a CSensoryFrame is one
///    step: the odometry increment of its CActionRobotMovement2D/3D with that action's covariance,
///    then the landmarks of the frame's CObservationBearingRange. A sensory frame before the first
///    action and an action without a following frame are skipped, as MRPT's kf-slam does, so step k
///    is observed at row k + 1 of the demo ground-truth paths.
///  - observation-only rawlogs: each CObservationOdometry starts a step whose increment is the
///    change of the absolute odometry reading (noise from RawlogOptions, the reading has none);
///    CObservationBearingRange entries add to the current step.
/// A step whose increment is exactly zero is a robot at rest (RawlogOptions::at_rest_noise_scale).
/// The sensor mount and noise come from the CObservationBearingRange entries (or RawlogOptions)
/// and must not change along the log. Anything the reader cannot use gives a parse_error naming
/// the file, the entry and the problem.

#include <Eigen/Core>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <mrpt/io/CFileGZInputStream.h>
#include <mrpt/obs/CActionCollection.h>
#include <mrpt/obs/CActionRobotMovement2D.h>
#include <mrpt/obs/CActionRobotMovement3D.h>
#include <mrpt/obs/CObservationBearingRange.h>
#include <mrpt/obs/CObservationOdometry.h>
#include <mrpt/obs/CSensoryFrame.h>
#include <mrpt/poses/CPose3DPDFGaussian.h>
#include <mrpt/poses/CPosePDFGaussian.h>
#include <mrpt/serialization/CArchive.h>
#include <optional>
#include <set>
#include <string>
#include <variant>
#include <vector>

#include "sextant/core/error.hpp"
#include "sextant/core/gaussian.hpp"
#include "sextant/core/observation.hpp"
#include "sextant/io/ids_from_ground_truth.hpp"
#include "sextant/io/input_file.hpp"
#include "sextant/io/kf_slam_ground_truth.hpp"
#include "sextant/io/landmark_dataset.hpp"
#include "sextant/mrpt/exception_text.hpp"
#include "sextant/mrpt/rawlog_options.hpp"
#include "sextant/models/range_bearing_2d.hpp"
#include "sextant/models/range_bearing_3d.hpp"
#include "sextant/models/se2_odometry.hpp"
#include "sextant/models/se3_odometry.hpp"

/// Adapters between sextant and MRPT. Not `sextant::mrpt`: inside namespace sextant that name
/// would hide ::mrpt for every user who writes `using namespace sextant`.
namespace sextant::mrpt_io {

/// A rawlog as a step stream with the models configured from it; ground truth when attached.
template <class MotionT, class SensorT>
using RawlogDataset = io::LandmarkDataset<MotionT, SensorT>;

using RawlogDataset2D = RawlogDataset<Se2Odometry, RangeBearing2D>;
using RawlogDataset3D = RawlogDataset<Se3Odometry, RangeBearing3D>;

/// Whether a rawlog's robot moves in the plane (2D odometry, all pitches zero) or in space.
enum class RawlogKind { planar, spatial };

namespace detail {

/// Every serialized object of the file, in order.
inline std::vector<::mrpt::serialization::CSerializable::Ptr> read_objects(const std::string& path) {
  io::require_input_file(path);
  ::mrpt::io::CFileGZInputStream in;
  if (!in.open(path)) throw parse_error(path + ": cannot open file");
  auto archive = ::mrpt::serialization::archiveFrom(in);
  std::vector<::mrpt::serialization::CSerializable::Ptr> objects;
  for (;;) {
    const auto start = in.getPosition();
    try {
      objects.push_back(archive.ReadObject());
    } catch (const std::exception& e) {
      if (in.getPosition() == start) break;  // nothing of a next entry: the end of the log
      const std::string entry = path + ": entry " + std::to_string(objects.size()) + ": ";
      if (const auto name = unreadable_class(e.what()))  // anywhere in the text: nested objects nest the errors
        throw parse_error(entry + "an object of class " + *name + ", which this reader cannot read; it reads landmark " +
                          "logs (odometry and CObservationBearingRange), and a rawlog's entries cannot be skipped");
      throw parse_error(entry + "truncated or malformed rawlog (" + exception_message(e.what()) + ")");
    }
    if (!objects.back()) throw parse_error(path + ": entry " + std::to_string(objects.size() - 1) + ": empty object");
  }
  if (objects.empty()) throw parse_error(path + ": empty rawlog (no entries)");
  return objects;
}

inline double seconds_of(const ::mrpt::Clock::time_point& t) { return ::mrpt::Clock::toDouble(t); }

/// A range-bearing reading in common form before it becomes a 2D or 3D measurement.
struct Sighting {
  LandmarkId id;
  Eigen::Vector3d range_yaw_pitch;
};

/// One step before model-specific conversion: the odometry (6D, MRPT's x y z yaw pitch roll order)
/// and what the sensor saw.
struct RawStep {
  Vector6d delta = Vector6d::Zero();
  Matrix6d cov = Matrix6d::Zero();
  bool planar_odometry = true;
  double time = 0.0;  ///< seconds; 0 when the log has no time stamps
  std::vector<Sighting> sightings;
};

/// The sensor as the rawlog describes it; every frame must agree with the first.
struct SensorDescription {
  Vector6d mount = Vector6d::Zero();
  Eigen::Vector3d std_range_yaw_pitch = Eigen::Vector3d::Zero();
  bool known = false;
};

/// A CPose3D as (x, y, z, yaw, pitch, roll).
inline Vector6d to_vector(const ::mrpt::poses::CPose3D& p) {
  return (Vector6d() << p.x(), p.y(), p.z(), p.yaw(), p.pitch(), p.roll()).finished();
}

class RawlogParser {
 public:
  explicit RawlogParser(std::string path) : path_(std::move(path)) {}

  std::vector<RawStep> parse(const RawlogOptions& options) {
    const auto objects = read_objects(path_);
    for (std::size_t i = 0; i < objects.size(); ++i) {
      entry_ = i;
      const auto& object = objects[i];
      if (auto actions = std::dynamic_pointer_cast<::mrpt::obs::CActionCollection>(object))
        on_actions(*actions);
      else if (auto frame = std::dynamic_pointer_cast<::mrpt::obs::CSensoryFrame>(object))
        on_frame(*frame);
      else if (auto odometry = std::dynamic_pointer_cast<::mrpt::obs::CObservationOdometry>(object))
        on_odometry(*odometry, options);
      else if (auto bearing = std::dynamic_pointer_cast<::mrpt::obs::CObservationBearingRange>(object))
        on_bearing_range(*bearing);
      // Other observations (images, scans, ...) are not used by landmark SLAM.
      if (options.max_steps && steps_.size() > options.max_steps) break;
    }
    if (options.max_steps && steps_.size() > options.max_steps) steps_.resize(options.max_steps);
    if (steps_.empty()) throw parse_error(path_ + ": no odometry step followed by observations");
    if (!sensor_.known) throw parse_error(path_ + ": no CObservationBearingRange entries");
    for (auto& step : steps_)
      if (step.delta.isZero(0.0)) step.cov *= options.at_rest_noise_scale * options.at_rest_noise_scale;
    return std::move(steps_);
  }

  const SensorDescription& sensor() const { return sensor_; }
  /// Whether the landmarks carry ids (false: MRPT's landmarkID = -1 throughout).
  bool has_ids() const { return ids_.value_or(true); }
  /// The readings dropped on the way (drop_non_positive_range), for warnings.
  const io::ImplausibleValues& implausible() const { return implausible_; }

 private:
  [[noreturn]] void fail(const std::string& problem) const {
    throw parse_error(path_ + ": entry " + std::to_string(entry_) + ": " + problem);
  }

  void on_actions(const ::mrpt::obs::CActionCollection& actions) {
    if (pending_) fail("two odometry actions without a sensory frame between them");
    RawStep step;
    if (auto move3d = actions.getActionByClass<::mrpt::obs::CActionRobotMovement3D>()) {
      step.delta = to_vector(move3d->poseChange.mean);
      step.cov = move3d->poseChange.cov.asEigen();
      step.planar_odometry = false;
    } else if (auto move2d = actions.getBestMovementEstimation()) {
      const ::mrpt::poses::CPosePDFGaussian gaussian(*move2d->poseChange);
      step.delta << gaussian.mean.x(), gaussian.mean.y(), 0.0, gaussian.mean.phi(), 0.0, 0.0;
      const std::array<int, 3> planar{0, 1, 3};
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) step.cov(planar[r], planar[c]) = gaussian.cov(r, c);
    } else {
      fail("action collection without a CActionRobotMovement2D or CActionRobotMovement3D");
    }
    if (!step.delta.allFinite() || !step.cov.allFinite()) fail("odometry contains NaN or Inf");
    pending_ = std::move(step);
  }

  void on_frame(const ::mrpt::obs::CSensoryFrame& frame) {
    if (!pending_) return;  // a frame before the first action: skipped, as in MRPT's kf-slam
    RawStep step = std::move(*pending_);
    pending_.reset();
    for (const auto& observation : frame)
      if (auto bearing = std::dynamic_pointer_cast<::mrpt::obs::CObservationBearingRange>(observation))
        add_sightings(*bearing, step);
    steps_.push_back(std::move(step));
  }

  void on_odometry(const ::mrpt::obs::CObservationOdometry& odometry, const RawlogOptions& options) {
    const Eigen::Vector3d reading(odometry.odometry.x(), odometry.odometry.y(), odometry.odometry.phi());
    if (!reading.allFinite()) fail("odometry reading contains NaN or Inf");
    if (last_odometry_) {
      const ::mrpt::poses::CPose2D change = odometry.odometry - *last_odometry_;
      RawStep step;
      step.delta << change.x(), change.y(), 0.0, change.phi(), 0.0, 0.0;
      step.cov(0, 0) = options.odometry_std(0) * options.odometry_std(0);
      step.cov(1, 1) = options.odometry_std(1) * options.odometry_std(1);
      step.cov(3, 3) = options.odometry_std(2) * options.odometry_std(2);
      steps_.push_back(std::move(step));
    }
    last_odometry_ = odometry.odometry;
  }

  void on_bearing_range(const ::mrpt::obs::CObservationBearingRange& bearing) {
    if (steps_.empty()) return;  // seen before the first odometry step: skipped
    add_sightings(bearing, steps_.back());
  }

  void add_sightings(const ::mrpt::obs::CObservationBearingRange& bearing, RawStep& step) {
    describe_sensor(bearing);
    const double time = seconds_of(bearing.timestamp);
    if (std::isfinite(time)) step.time = time;
    std::set<LandmarkId> seen;
    for (const auto& s : step.sightings) seen.insert(s.id);
    for (const auto& m : bearing.sensedData) {
      const bool with_id = m.landmarkID >= 0;
      note_id_kind(with_id);
      const std::string which = with_id ? "landmark " + std::to_string(m.landmarkID) : "a landmark without id";
      const Eigen::Vector3d z(m.range, m.yaw, m.pitch);
      if (!z.allFinite()) fail(which + ": measurement contains NaN or Inf");
      if (!(z(0) > 0.0)) {
        drop_non_positive_range(which, z(0));
        continue;
      }
      const LandmarkId id = with_id ? static_cast<LandmarkId>(m.landmarkID) : io::kNoLandmarkId;
      if (with_id && !seen.insert(id).second) fail(which + " measured twice in one frame");
      step.sightings.push_back({id, z});
    }
  }

  /// A range sensor with Gaussian noise reports a landmark next to it at a range <= 0 now and then
  /// (MRPT's simul-landmarks writes 0 where its noise takes the true range below zero): a reading no
  /// model here can invert into a landmark, in a log that is otherwise sound. Dropped and listed.
  void drop_non_positive_range(const std::string& which, double range) {
    char text[96];
    std::snprintf(text, sizeof text, ": range %.6g m is not positive: the sighting is dropped", range);
    implausible_.record(path_ + ": entry " + std::to_string(entry_) + ": " + which + text);
  }

  /// A log gives every landmark an id (landmarkID >= 0) or none (-1, MRPT's "unknown"), not both.
  void note_id_kind(bool with_id) {
    if (!ids_) ids_ = with_id;
    else if (*ids_ != with_id)
      fail("some landmarks have ids and some have none (landmarkID = -1): a log must be one or the other");
  }

  void describe_sensor(const ::mrpt::obs::CObservationBearingRange& bearing) {
    if (bearing.validCovariances) fail("per-landmark covariances (validCovariances) are not supported");
    SensorDescription d;
    d.mount = to_vector(bearing.sensorLocationOnRobot);
    d.std_range_yaw_pitch << bearing.sensor_std_range, bearing.sensor_std_yaw, bearing.sensor_std_pitch;
    d.known = true;
    if (!d.mount.allFinite() || !d.std_range_yaw_pitch.allFinite()) fail("sensor description contains NaN or Inf");
    if (!sensor_.known) {
      sensor_ = d;
    } else if ((sensor_.mount - d.mount).norm() > 1e-9) {
      fail("the sensor moved on the robot (sensorLocationOnRobot changed)");
    } else if ((sensor_.std_range_yaw_pitch - d.std_range_yaw_pitch).norm() > 1e-9) {
      fail("the sensor noise changed along the log");
    }
  }

  std::string path_;
  std::size_t entry_ = 0;
  std::vector<RawStep> steps_;
  std::optional<RawStep> pending_;
  std::optional<::mrpt::poses::CPose2D> last_odometry_;
  SensorDescription sensor_;
  std::optional<bool> ids_;  ///< whether the landmarks seen so far had ids
  io::ImplausibleValues implausible_;
};

/// The noise standard deviation to use: the override if given, else the rawlog's (which must be > 0).
inline double noise_std(const std::optional<double>& override_value, double from_log, const std::string& path,
                        const char* name) {
  const double value = override_value ? *override_value : from_log;
  if (!(value > 0.0) || !std::isfinite(value))
    throw parse_error(path + ": sensor " + name + " noise is " + std::to_string(value) +
                      (override_value ? " (from the options)" : " in the rawlog; give it in the options"));
  return value;
}


inline double step_dt(const std::vector<RawStep>& steps, std::size_t k) {
  const double previous = k == 0 ? 0.0 : steps[k - 1].time;
  const double dt = steps[k].time - previous;
  return (k > 0 && previous > 0.0 && dt > 0.0 && std::isfinite(dt)) ? dt : 1.0;
}

}  // namespace detail

namespace detail {

/// Spatial as soon as the log has 3D odometry, a nonzero pitch or a sensor mounted out of the plane.
inline bool is_spatial(const std::vector<RawStep>& steps, const SensorDescription& sensor) {
  for (const auto& step : steps) {
    if (!step.planar_odometry) return true;
    for (const auto& s : step.sightings)
      if (s.range_yaw_pitch(2) != 0.0) return true;
  }
  return sensor.mount(2) != 0.0 || !sensor.mount.tail<2>().isZero();
}

/// What a dataset says of the log beside its steps: where it came from, whether its landmarks carry
/// ids, the readings the parser dropped.
template <class Dataset>
void describe_log(Dataset& out, const std::string& path, const RawlogParser& parser) {
  out.path = path;
  out.ids = parser.has_ids() ? io::LandmarkIds::measured : io::LandmarkIds::absent;
  out.implausible = parser.implausible();
}

/// The parsed log as planar steps: (x, y, heading) odometry (3D odometry projected onto the
/// plane), range and bearing; a nonzero pitch is an error.
inline RawlogDataset2D to_planar(const std::string& path, const std::vector<RawStep>& raw, const RawlogParser& parser,
                                 const RawlogOptions& options) {
  RawlogDataset2D out;
  describe_log(out, path, parser);
  const SensorDescription& sensor = parser.sensor();
  out.sensor.sensor_pose << sensor.mount(0), sensor.mount(1), sensor.mount(3);
  const double sr = noise_std(options.std_range, sensor.std_range_yaw_pitch(0), path, "range");
  const double sy = noise_std(options.std_yaw, sensor.std_range_yaw_pitch(1), path, "yaw");
  out.sensor.Q = Eigen::Vector2d(sr * sr, sy * sy).asDiagonal();
  out.prior.mean.setZero();
  out.prior.cov = Eigen::Matrix3d::Identity() * options.prior_std * options.prior_std;
  const std::array<int, 3> planar{0, 1, 3};
  for (std::size_t k = 0; k < raw.size(); ++k) {
    Step<OdometryIncrement2D, Eigen::Vector2d> step;
    for (int r = 0; r < 3; ++r) {
      step.control.delta(r) = raw[k].delta(planar[r]);
      for (int c = 0; c < 3; ++c) step.control.cov(r, c) = raw[k].cov(planar[r], planar[c]);
    }
    step.dt = step_dt(raw, k);
    for (const auto& s : raw[k].sightings) {
      if (s.range_yaw_pitch(2) != 0.0)
        throw parse_error(path + ": step " + std::to_string(k) + ": landmark " + std::to_string(s.id) +
                          " has pitch != 0: read this rawlog as spatial (3D)");
      step.observations.push_back({s.id, s.range_yaw_pitch.head<2>()});
    }
    out.steps.push_back(std::move(step));
  }
  return out;
}

/// The parsed log as spatial steps: 6D odometry, range, yaw and pitch; 2D odometry is an error.
inline RawlogDataset3D to_spatial(const std::string& path, const std::vector<RawStep>& raw, const RawlogParser& parser,
                                  const RawlogOptions& options) {
  RawlogDataset3D out;
  describe_log(out, path, parser);
  const SensorDescription& sensor = parser.sensor();
  out.sensor.sensor_pose = sensor.mount;
  const double sr = noise_std(options.std_range, sensor.std_range_yaw_pitch(0), path, "range");
  const double sy = noise_std(options.std_yaw, sensor.std_range_yaw_pitch(1), path, "yaw");
  const double sp = noise_std(options.std_pitch, sensor.std_range_yaw_pitch(2), path, "pitch");
  out.sensor.Q = Eigen::Vector3d(sr * sr, sy * sy, sp * sp).asDiagonal();
  out.prior.mean.setZero();
  out.prior.cov = Matrix6d::Identity() * options.prior_std * options.prior_std;
  for (std::size_t k = 0; k < raw.size(); ++k) {
    if (raw[k].planar_odometry)
      throw parse_error(path + ": step " + std::to_string(k) + ": 2D odometry in a spatial rawlog: read it as planar");
    Step<OdometryIncrement3D, Eigen::Vector3d> step;
    step.control.delta = raw[k].delta;
    step.control.cov = raw[k].cov;
    step.dt = step_dt(raw, k);
    for (const auto& s : raw[k].sightings) step.observations.push_back({s.id, s.range_yaw_pitch});
    out.steps.push_back(std::move(step));
  }
  return out;
}

}  // namespace detail

/// Planar or spatial: spatial as soon as the log has 3D odometry or a nonzero pitch.
inline RawlogKind detect_rawlog_kind(const std::string& path, const RawlogOptions& options = {}) {
  detail::RawlogParser parser(path);
  const auto raw = parser.parse(options);
  return detail::is_spatial(raw, parser.sensor()) ? RawlogKind::spatial : RawlogKind::planar;
}

/// Reads a planar rawlog: (x, y, heading) robot, 2D odometry (3D odometry is projected onto the
/// plane), range and bearing. A nonzero pitch is an error.
inline RawlogDataset2D read_rawlog_2d(const std::string& path, const RawlogOptions& options = {}) {
  detail::RawlogParser parser(path);
  const auto raw = parser.parse(options);
  return detail::to_planar(path, raw, parser, options);
}

/// Reads a spatial rawlog: 6D robot, 6D odometry, range, yaw and pitch. 2D odometry is an error.
inline RawlogDataset3D read_rawlog_3d(const std::string& path, const RawlogOptions& options = {}) {
  detail::RawlogParser parser(path);
  const auto raw = parser.parse(options);
  return detail::to_spatial(path, raw, parser, options);
}

/// Reads a rawlog once as whichever it is, planar or spatial (see detect_rawlog_kind).
inline std::variant<RawlogDataset2D, RawlogDataset3D> read_rawlog(const std::string& path,
                                                                  const RawlogOptions& options = {}) {
  detail::RawlogParser parser(path);
  const auto raw = parser.parse(options);
  if (detail::is_spatial(raw, parser.sensor())) return detail::to_spatial(path, raw, parser, options);
  return detail::to_planar(path, raw, parser, options);
}

/// The ground-truth files beside a rawlog, if both exist: `<stem>_ground_truth.txt` (map) and
/// `<stem>_ground_truth_robot_path.txt` (path) as MRPT's demo logs ship them, or
/// `<name>.rawlog_ground_truth.txt` and `<name>.rawlog_ground_truth_robot_path.txt` as MRPT's
/// simul-landmarks writes them.
struct GroundTruthFiles {
  std::string map, path;
};
inline std::optional<GroundTruthFiles> find_ground_truth(const std::string& rawlog_path) {
  const std::filesystem::path p(rawlog_path);
  for (const auto& stem : {(p.parent_path() / p.stem()).string(), rawlog_path}) {
    GroundTruthFiles files{stem + "_ground_truth.txt", stem + "_ground_truth_robot_path.txt"};
    if (std::filesystem::exists(files.map) && std::filesystem::exists(files.path)) return files;
  }
  return std::nullopt;
}

/// Attaches ground truth: path row k is the pose after step k (row 0 the start); the path must
/// cover every step and start where the rawlog does (the origin), and the map must hold every
/// observed landmark. A log without landmark ids gets them from the truth
/// (io/ids_from_ground_truth.hpp), with how clear-cut they were.
template <class Dataset>
std::optional<io::InferredIds> attach_ground_truth(Dataset& data, const GroundTruthFiles& files) {
  constexpr int D = Dataset::Sensor::Landmark::RowsAtCompileTime;
  const auto path = io::read_kf_slam_path(files.path);
  if (path.size() < data.steps.size() + 1)
    throw parse_error(files.path + ": " + std::to_string(path.size()) + " poses for " + std::to_string(data.steps.size()) +
                      " steps (need one more than steps)");
  data.true_poses.clear();
  for (std::size_t k = 0; k <= data.steps.size(); ++k) {
    if constexpr (Dataset::Motion::kDim == 3)
      data.true_poses.emplace_back(path[k](0), path[k](1), path[k](3));
    else
      data.true_poses.push_back(path[k]);
  }
  data.true_landmarks = io::read_kf_slam_landmarks<D>(files.map);
  if (data.ids == io::LandmarkIds::absent) return io::infer_ids_from_ground_truth(data);
  for (const auto& step : data.steps)
    for (const auto& o : step.observations)
      if (!data.true_landmarks.count(o.landmark_id))
        throw parse_error(files.map + ": no ground truth for observed landmark " + std::to_string(o.landmark_id));
  return std::nullopt;
}

}  // namespace sextant::mrpt_io
