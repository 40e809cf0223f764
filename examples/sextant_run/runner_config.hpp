#pragma once
// sextant-run's settings: defaults, and an MRPT-style ini file (mrpt::config::CConfigFile) with one
// section per back-end and per data source. Every key is declared once below, with its default and
// its meaning; `sextant-run --print-config` prints them as an ini file (docs/runner.md holds that
// output, checked by a test). An unknown section or key, or a value that does not parse, is an
// error naming the file, the section and the key.
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <cstdio>
#include <limits>
#include <filesystem>
#include <functional>
#include <initializer_list>
#include <mrpt/config/CConfigFile.h>
#include <numbers>
#include <optional>
#include <sextant/backends/ekf_slam.hpp>
#include <sextant/backends/fast_slam.hpp>
#include <sextant/backends/graph_slam.hpp>
#include <sextant/backends/pose_graph.hpp>
#include <sextant/backends/seif_slam.hpp>
#include <sextant/core/data_association.hpp>
#include <sextant/core/error.hpp>
#include <sextant/io/mrclam_reader.hpp>
#include <sextant/io/parse_number.hpp>
#include <sextant/mrpt/exception_text.hpp>
#include <sextant/mrpt/rawlog_options.hpp>
#include <sextant/core/landmark_pool_policy.hpp>
#include <sextant/sim/ship_2d.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "table_row.hpp"

namespace sextant::runner {

/// The globe experiment's settings; run_globe.cpp turns them into sim::GlobeCameraOptions (kept apart
/// so that the main job's translation units do not parse the 12D camera and its simulator).
struct GlobeSettings {
  std::uint64_t seed = 1;
  int steps = 500;                ///< thesis: 500
  int points = 3000;              ///< feature points on the globe
  int features_per_frame = 120;   ///< strongest visible points observed per frame
  double response_jitter = 0.0;   ///< the detector's frame-to-frame response noise (sim::GlobeCameraOptions)
  PoolLimits pool{.max_landmarks = 1000, .max_new_per_step = 50};  ///< thesis: Mmax = 1000, 50 new per step
  std::vector<std::size_t> seif_active{150, 250, 0};  ///< one SEIF run per value (0 = all active)
  /// One more SEIF run per value with relocalization (ESEIF, the consistent sparsification), whatever
  /// [seif] sparsification says; empty = none.
  std::vector<std::size_t> eseif_active{150, 250};
  std::size_t covariance_period = 10;  ///< pose NEES every this many steps
  int graph_updates = 10;              ///< GraphSLAM global updates after the windowed initialization
  bool graph_batch = true;             ///< [globe] graph: the thesis's batch GraphSLAM row
  bool graph_online = false;           ///< [globe] graph: the online (incremental) GraphSLAM row
  std::size_t graph_lag = 0;           ///< [globe] graph_lag: the online row's fixed lag (0: exact)
  /// globe-stereo and stereo:DIR: the back-end that tracks the images online and gates the association
  BackendKind tracker = BackendKind::ekf;
  /// [globe] tracker_gate: a SEIF tracker gates with the exact joint marginal (a factorization of
  /// Omega a frame) instead of the robot and each landmark conditioned on the rest of the map
  bool tracker_exact_gate = false;
  int octave_layers = 4;            ///< globe-stereo, stereo:DIR: AKAZE's sublevels per octave (vision::DetectorOptions)
  double detector_threshold = 0.001;  ///< globe-stereo, stereo:DIR: AKAZE's response threshold
  bool orb = false;                 ///< [globe] detector = orb: ORB instead of AKAZE (vision::Detector)
  int orb_levels = 8;               ///< globe-stereo, stereo:DIR: ORB's pyramid levels (vision::DetectorOptions)
  double min_disparity_sigmas = 0.0;  ///< globe-stereo, stereo:DIR: stereo matches within this many std of zero disparity dropped
  bool slant_noise = false;  ///< globe-stereo, stereo:DIR: FrontEndOptions::slant_noise
  bool disparity_support = false;  ///< globe-stereo, stereo:DIR: FrontEndOptions::disparity_support
  double new_landmark_density = 0.0;  ///< per m^3, globe-stereo, stereo:DIR: MapAssociationOptions::new_landmark_density
  double student_t_dof = 0.0;  ///< globe-stereo, stereo:DIR: MapAssociationOptions::student_t_dof
  std::size_t returning_after = 0;  ///< globe-stereo, stereo:DIR: ReturningLandmarkOptions::after_frames
  double returning_window = 0.05;   ///< globe-stereo, stereo:DIR: ReturningLandmarkOptions::window
  bool row_search = false;  ///< [globe] stereo_correspondence = row_search: no detection in the right image
  int right_refinement_px = 0;  ///< globe-stereo, stereo:DIR: FrontEndOptions::right_refinement.radius
  bool slanted_correlation = false;  ///< globe-stereo, stereo:DIR: FrontEndOptions::slanted_correlation
  bool drop_unmeasured_disparities = false;  ///< globe-stereo, stereo:DIR: SlantedCorrelationOptions::drop_unmeasured
  double disparity_sigma = 0.0;  ///< px, globe-stereo, stereo:DIR: StereoPointNoise::disparity_sigma of the image observations
  std::uint64_t texture_seed = 1;  ///< globe-stereo: sim::GlobeRenderOptions::texture_seed (the globe's pattern)
  bool pipelined = true;    ///< globe-stereo, stereo:DIR: frame k+1's front-end during frame k's filter half
  int opencv_threads = 1;   ///< globe-stereo, stereo:DIR: cv::setNumThreads during the run (0: OpenCV's default)
};

/// The visual-inertial runs' settings (run_vislam.cpp): the models' noise for .npz data (the
/// simulator brings its own), the landmark pool and the gate.
struct VislamSettings {
  double velocity_sigma = 0.5;  ///< m/s per axis, noise of the IMU's linear velocity (.npz data)
  double rate_sigma = 0.05;     ///< rad/s per axis, noise of its angular velocity (.npz data)
  double pixel_sigma = 2.0;     ///< px, feature noise (.npz data)
  double min_disparity = 2.0;   ///< px, smallest disparity a new landmark is triangulated from (.npz data)
  PoolLimits pool{.max_landmarks = 150, .max_new_per_step = 20};
  double gate_probability = 0.999;  ///< Mahalanobis gate of the filters
  std::uint64_t seed = 1;           ///< stereo-vi simulation
  int steps = 400;                  ///< stereo-vi frames (one loop)
};

/// Measurement ids withheld and found again by data association (EKF and SEIF), or used as given.
struct AssociationSettings {
  std::optional<AssociationMethod> method;  ///< none: the data set's ids are used
  AssociationOptions options;
};

/// A filter setting that `automatic` turns on where it helps, from the models (backend_factory.hpp):
/// [ekf] and [seif] first_estimate_jacobians where the pose is perturbed in the world frame ([mrclam]
/// and [isam] filters_in_world_frame), the chart in which they keep the global pose unobservable (in the
/// additive chart they would also need the motion Jacobian at first estimates, and alone they make
/// the EKF worse, docs/results/mrclam.md); observability_constraints where the state space names the
/// world's rigid motions (the globe's 12D camera, docs/derivations/observability_constraints.md).
enum class AutoSwitch { automatic, on, off };

/// Where a pose graph's optimization starts ([pose_graph] start).
enum class PoseGraphStart {
  file,           ///< the file's vertices (a spanning tree of the odometry when it has none)
  spanning_tree,  ///< PoseGraph::initialize_by_spanning_tree
  chordal,        ///< PoseGraph::initialize_by_chordal_relaxation
};

struct RunnerConfig {
  sim::Ship2DOptions ship;
  int ship_runs = 10;
  mrpt_io::RawlogOptions rawlog;
  EkfOptions ekf;
  AutoSwitch ekf_first_estimates = AutoSwitch::automatic;
  AutoSwitch seif_first_estimates = AutoSwitch::automatic;
  AutoSwitch ekf_observability_constraints = AutoSwitch::automatic;
  AutoSwitch seif_observability_constraints = AutoSwitch::automatic;
  SeifOptions seif{.max_active = 8};
  std::optional<SeifEstimate> seif_estimate;              ///< nullopt: auto (backend_factory.hpp)
  std::optional<double> seif_stale_mean_probability;      ///< nullopt: auto (backend_factory.hpp)
  GraphOptions graph;
  PoseGraphOptions pose_graph;
  PoseGraphStart pose_graph_start = PoseGraphStart::file;
  FastSlamOptions fastslam{.particles = 100, .resample_threshold = 0.1, .map_estimate = FastSlamMap::weighted_average};
  GlobeSettings globe;
  VislamSettings vislam;
  io::MrclamOptions mrclam;
  bool mrclam_filters_in_world_frame = true;  ///< [mrclam] filters_in_world_frame
  bool isam_filters_in_world_frame = true;    ///< [isam] filters_in_world_frame (docs/results/victoria_park.md)
  std::size_t isam_graph_window = 1000;       ///< [isam] graph_window: GraphSLAM's, set over [graph] window
  /// [mrclam] gate_probability and graph_robust_kernel: what docs/results/mrclam.md recommends for
  /// real robots (heavy-tailed outliers), set on the back-ends for MRCLAM runs whatever [ekf], [seif]
  /// gate_probability and [graph] robust_kernel say; FastSLAM keeps [fastslam] gate_probability.
  double mrclam_gate_probability = 0.9999;
  RobustKernel mrclam_graph_kernel = RobustKernel::cauchy;
  int mrclam_reacquire_after_landmarks = 3;  ///< [mrclam] reacquire_after_landmarks (docs/results/mrclam.md, stress cases)
  AssociationSettings association;
  double scene_quantile = 3.0;
};

/// One settable key: where it lives, its default as text, what it means, how it is applied.
struct ConfigKey {
  std::string section, key, default_value, meaning;
  std::function<void(RunnerConfig&, const std::string& value)> apply;
};

namespace detail {

inline double parse_number(const std::string& text) {
  const auto value = io::parse_finite_number(text);
  if (!value) throw invalid_input_error("'" + text + "' is not a finite number");
  return *value;
}

/// `text` when it is one of `choices`; else invalid_input_error "'text' is not a WHAT (a, b or c)".
inline const std::string& one_of(const std::string& text, std::initializer_list<const char*> choices, const char* what) {
  std::string list;
  std::size_t k = 0;
  for (const char* choice : choices) {
    if (text == choice) return text;
    list += (k == 0 ? "" : k + 1 == choices.size() ? " or " : ", ") + std::string(choice);
    ++k;
  }
  throw invalid_input_error("'" + text + "' is not a " + what + " (" + list + ")");
}

/// An integer of type T in [min, max], max at most T's largest value or 2^53 (the largest up to which
/// every integer is a double), whichever is smaller: no value is silently truncated. Counts that
/// size memory (steps, particles, landmarks) pass their documented limit as `limit`
/// (docs/reliability.md), so that a typo is an error naming the key, not std::bad_alloc.
template <class T>
T parse_integer(const std::string& text, long long min, double limit = 9007199254740992.0) {
  const double value = parse_number(text);
  const double max = std::min({static_cast<double>(std::numeric_limits<T>::max()), 9007199254740992.0, limit});
  if (value != std::floor(value) || value < static_cast<double>(min) || value > max) {
    char range[64];
    std::snprintf(range, sizeof range, "[%lld, %.0f]", min, max);
    throw invalid_input_error("'" + text + "' is not an integer in " + range);
  }
  return static_cast<T>(value);
}

inline bool parse_bool(const std::string& text) {
  if (text == "true" || text == "1" || text == "yes") return true;
  if (text == "false" || text == "0" || text == "no") return false;
  throw invalid_input_error("'" + text + "' is not true or false");
}

inline double positive(double value, const std::string& text) {
  if (!(value > 0.0)) throw invalid_input_error("'" + text + "' must be positive");
  return value;
}

inline double non_negative(double value, const std::string& text) {
  if (!(value >= 0.0)) throw invalid_input_error("'" + text + "' must be >= 0");
  return value;
}

/// The value without a trailing `// comment` (MRPT's ini files use them) and surrounding blanks.
inline std::string without_comment(std::string value) {
  if (const auto comment = value.find("//"); comment != std::string::npos) value.erase(comment);
  const auto first = value.find_first_not_of(" \t\r");
  const auto last = value.find_last_not_of(" \t\r");
  return first == std::string::npos ? std::string() : value.substr(first, last - first + 1);
}

/// A probability in (0, 1).
inline double parse_probability(const std::string& text) {
  const double p = parse_number(text);
  if (!(p > 0.0 && p < 1.0)) throw invalid_input_error("'" + text + "' must be in (0, 1)");
  return p;
}

/// A factor in (0, 1].
inline double parse_fraction(const std::string& text) {
  const double p = parse_number(text);
  if (!(p > 0.0 && p <= 1.0)) throw invalid_input_error("'" + text + "' must be in (0, 1]");
  return p;
}

/// A gate probability: 0 (off) or in (0, 1).
inline double parse_gate_probability(const std::string& text) {
  const double p = parse_number(text);
  if (p < 0.0 || p >= 1.0) throw invalid_input_error("'" + text + "' must be in [0, 1)");
  return p;
}

/// A list of active-landmark counts ("150 250 0"); with `relocalizing`, counts of at least 1 or
/// "none" (an empty list).
inline std::vector<std::size_t> parse_active_counts(const std::string& text, bool relocalizing) {
  if (relocalizing && text == "none") return {};
  std::istringstream in(text);
  std::vector<std::size_t> values;
  for (std::string word; in >> word;) values.push_back(parse_integer<std::size_t>(word, relocalizing ? 1 : 0, 1e6));
  if (values.empty()) throw invalid_input_error("'" + text + "' lists no value");
  return values;
}

template <class Enum>
Enum parse_choice(const std::string& text, std::initializer_list<std::pair<const char*, Enum>> choices) {
  std::string names;
  for (const auto& [name, value] : choices) {
    if (text == name) return value;
    names += names.empty() ? name : std::string("|") + name;
  }
  throw invalid_input_error("'" + text + "' is not one of " + names);
}

inline AutoSwitch parse_auto_switch(const std::string& text) {
  return parse_choice<AutoSwitch>(text, {{"auto", AutoSwitch::automatic}, {"true", AutoSwitch::on}, {"false", AutoSwitch::off}});
}

}  // namespace detail

namespace detail {

/// [ship]: the simulated 2D beacon ship's Monte Carlo runs.
inline std::vector<ConfigKey> ship_keys() {
  constexpr double deg = std::numbers::pi / 180.0;
  return {
    {"ship", "seed", "1", "first simulation seed of the 2D beacon-ship Monte Carlo runs",
     [](RunnerConfig& c, const std::string& v) { c.ship.seed = parse_integer<std::uint64_t>(v, 0); }},
    {"ship", "runs", "10", "Monte Carlo runs (seeds seed .. seed+runs-1); the table averages them",
     [](RunnerConfig& c, const std::string& v) { c.ship_runs = parse_integer<int>(v, 1, 1e5); }},
    {"ship", "steps", "1390", "steps per run (thesis: 1390)",
     [](RunnerConfig& c, const std::string& v) { c.ship.num_steps = parse_integer<int>(v, 1, 1e7); }},
    {"ship", "sigma_heading_deg", "15", "compass noise, degrees (thesis: 15)",
     [](RunnerConfig& c, const std::string& v) { c.ship.sigma_heading = positive(parse_number(v), v) * deg; }},
    {"ship", "sigma_beacon", "2", "beacon offset noise per axis, km",
     [](RunnerConfig& c, const std::string& v) { c.ship.sigma_beacon = positive(parse_number(v), v); }},
  };
}

/// [globe]: the globe (12D camera) simulation, its pool and its filter runs.
inline std::vector<ConfigKey> globe_keys() {
  return {
    {"globe", "seed", "1", "simulation seed of the globe (12D camera) experiment",
     [](RunnerConfig& c, const std::string& v) { c.globe.seed = parse_integer<std::uint64_t>(v, 0); }},
    {"globe", "texture_seed", "1",
     "globe-stereo: seed of the globe's procedural texture (another value renders another pattern on the same "
     "orbit: a world the front-end's settings were not chosen on)",
     [](RunnerConfig& c, const std::string& v) { c.globe.texture_seed = parse_integer<std::uint64_t>(v, 0); }},
    {"globe", "steps", "500", "steps (thesis: 500); the circle closes near step 420",
     [](RunnerConfig& c, const std::string& v) { c.globe.steps = parse_integer<int>(v, 1, 1e6); }},
    {"globe", "points", "3000", "feature points on the globe",
     [](RunnerConfig& c, const std::string& v) { c.globe.points = parse_integer<int>(v, 1, 1e7); }},
    {"globe", "features_per_frame", "120", "strongest visible points observed per frame",
     [](RunnerConfig& c, const std::string& v) { c.globe.features_per_frame = parse_integer<int>(v, 1, 1e5); }},
    {"globe", "response_jitter", "0",
     "log-normal frame-to-frame noise of the detector's responses (0 = the same strongest points every frame; "
     "1 with 20000 points and Mmax 10000: the thesis-scale run of docs/results/real_time.md)",
     [](RunnerConfig& c, const std::string& v) { c.globe.response_jitter = non_negative(parse_number(v), v); }},
    {"globe", "max_landmarks", "1000", "landmark pool capacity Mmax (thesis: 1000)",
     [](RunnerConfig& c, const std::string& v) { c.globe.pool.max_landmarks = parse_integer<std::size_t>(v, 1, 1e6); }},
    {"globe", "max_new_per_step", "50", "new landmarks per step at most (thesis: 50)",
     [](RunnerConfig& c, const std::string& v) { c.globe.pool.max_new_per_step = parse_integer<std::size_t>(v, 1, 1e6); }},
    {"globe", "pool_eviction", "least_recently_seen",
     "which landmarks make room in a full pool: least_recently_seen (thesis) | fewest_sightings (seen in the fewest "
     "steps first: tracked points stay for the loop) | fewest_sightings_without_fill (the same among those whose "
     "removal links nothing new in SEIF's information, then least recently seen)",
     [](RunnerConfig& c, const std::string& v) {
       c.globe.pool.eviction = parse_choice<PoolEviction>(
           v, {{"least_recently_seen", PoolEviction::least_recently_seen},
               {"fewest_sightings", PoolEviction::fewest_sightings},
               {"fewest_sightings_without_fill", PoolEviction::fewest_sightings_without_fill}});
     }},
    {"globe", "seif_active", "150 250 0", "SEIF runs, one per value: active landmarks (0 = all)",
     [](RunnerConfig& c, const std::string& v) { c.globe.seif_active = parse_active_counts(v, false); }},
    {"globe", "eseif_active", "150 250",
     "ESEIF runs (back-end eseif: SEIF with relocalization, consistent; docs/results/seif_relocalization.md), one "
     "per value: active landmarks (at least 1); 'none' = no such run",
     [](RunnerConfig& c, const std::string& v) { c.globe.eseif_active = parse_active_counts(v, true); }},
    {"globe", "covariance_period", "10", "NEES of the pose every this many steps (a SEIF's covariance costs a factorization)",
     [](RunnerConfig& c, const std::string& v) { c.globe.covariance_period = parse_integer<std::size_t>(v, 1); }},
  };
}

/// [globe]: the stereo front-end (globe-stereo, stereo:DIR) and its tracker.
inline std::vector<ConfigKey> globe_stereo_keys() {
  return {
    {"globe", "tracker", "ekf",
     "globe-stereo, stereo:DIR: the back-end that tracks the images and gates the association: ekf, seif (its "
     "first seif_active value, [seif]'s sparsification) or eseif (relocalizing, its first eseif_active value)",
     [](RunnerConfig& c, const std::string& v) {
       one_of(v, {"ekf", "seif", "eseif"}, "tracker");
       c.globe.tracker = v == "ekf" ? BackendKind::ekf : v == "seif" ? BackendKind::seif : BackendKind::eseif;
     }},
    {"globe", "tracker_gate", "conditional",
     "a SEIF tracker's gate: conditional (the robot and each landmark given the rest of the map, O(1) per "
     "landmark) | joint_marginal (exact: one solve with the factor of Omega a frame)",
     [](RunnerConfig& c, const std::string& v) {
       c.globe.tracker_exact_gate = one_of(v, {"conditional", "joint_marginal"}, "tracker gate") == "joint_marginal";
     }},
    {"globe", "octave_layers", "4",
     "globe-stereo, stereo:DIR: AKAZE's sublevels per octave (OpenCV's default 4; its time is mostly building them)",
     [](RunnerConfig& c, const std::string& v) { c.globe.octave_layers = parse_integer<int>(v, 1, 16); }},
    {"globe", "detector_threshold", "0.001", "globe-stereo, stereo:DIR: AKAZE's response threshold (OpenCV's default)",
     [](RunnerConfig& c, const std::string& v) { c.globe.detector_threshold = positive(parse_number(v), v); }},
    {"globe", "detector", "akaze",
     "globe-stereo, stereo:DIR: akaze (nonlinear scale space, 486-bit MLDB descriptors) | orb (FAST corners, "
     "256-bit steered BRIEF: a tenth of AKAZE's time; the association's descriptor distance follows the detector)",
     [](RunnerConfig& c, const std::string& v) { c.globe.orb = one_of(v, {"akaze", "orb"}, "detector") == "orb"; }},
    {"globe", "orb_levels", "8",
     "globe-stereo, stereo:DIR: ORB's pyramid levels, each 1.2 times coarser (OpenCV's default 8; 1: every corner "
     "at full resolution, no scale invariance)",
     [](RunnerConfig& c, const std::string& v) { c.globe.orb_levels = parse_integer<int>(v, 1, 16); }},
    {"globe", "min_disparity_sigmas", "0",
     "globe-stereo, stereo:DIR: stereo matches whose disparity is within this many of its standard deviations "
     "(sqrt(2) x the sensor's pixel noise) of zero are dropped, as points that cannot be told from one at infinity "
     "(0 keeps all; 2 drops below 1.41 px at 0.5 px noise)",
     [](RunnerConfig& c, const std::string& v) { c.globe.min_disparity_sigmas = non_negative(parse_number(v), v); }},
    {"globe", "slant_noise", "false",
     "globe-stereo, stereo:DIR: each stereo point's noise scaled by 1 / cos of the slant of the surface around it "
     "(the plane through the points within 40 px), at most 10x: oblique features weigh less",
     [](RunnerConfig& c, const std::string& v) { c.globe.slant_noise = parse_bool(v); }},
    {"globe", "disparity_support", "false",
     "globe-stereo, stereo:DIR: a stereo match is dropped when its disparity lies more than 4 standard deviations "
     "from the one predicted by the plane fitted (robustly) to the disparities of the others within 40 px (the radius "
     "doubled up to 160 px while they are fewer than 6): a wrong match off the surface around it",
     [](RunnerConfig& c, const std::string& v) { c.globe.disparity_support = parse_bool(v); }},
  };
}

/// [globe]: how the stereo tracker associates and how its pipeline runs (globe-stereo, stereo:DIR).
inline std::vector<ConfigKey> globe_stereo_association_keys() {
  return {
    {"globe", "new_landmark_density", "0",
     "globe-stereo, stereo:DIR: per m^3, how dense a new point is in view; a feature inside a landmark's gate that "
     "matches no descriptor becomes a new landmark when that landmark's predictive density there is below this "
     "(0: every gate keeps such a feature out)",
     [](RunnerConfig& c, const std::string& v) { c.globe.new_landmark_density = non_negative(parse_number(v), v); }},
    {"globe", "student_t_dof", "0",
     "globe-stereo, stereo:DIR: a re-observation's error as a Student-t of this many degrees of freedom: its noise "
     "scaled by sqrt((dof + NIS) / (dof + 3)) (0: Gaussian)",
     [](RunnerConfig& c, const std::string& v) { c.globe.student_t_dof = non_negative(parse_number(v), v); }},
    {"globe", "returning_after", "0",
     "globe-stereo, stereo:DIR: a landmark in view that its gate did not take and that was not seen for this many "
     "frames is matched by descriptor among the features within returning_window of its prediction, and taken when one rigid motion puts at least 10 such "
     "pairs inside their gates (the drift since a loop began; 0: off)",
     [](RunnerConfig& c, const std::string& v) { c.globe.returning_after = parse_integer<std::size_t>(v, 0); }},
    {"globe", "returning_window", "0.05",
     "globe-stereo, stereo:DIR: how far from its prediction a returning landmark's feature may lie, as a share of its "
     "distance from the camera (the drift it allows)",
     [](RunnerConfig& c, const std::string& v) { c.globe.returning_window = positive(parse_number(v), v); }},
    {"globe", "stereo_correspondence", "detect_both",
     "globe-stereo, stereo:DIR: detect_both (AKAZE in both images, matched along the rows by descriptor) | "
     "row_search (AKAZE in the left image only, each keypoint found along its row in the right by correlation)",
     [](RunnerConfig& c, const std::string& v) {
       c.globe.row_search = one_of(v, {"detect_both", "row_search"}, "stereo correspondence") == "row_search";
     }},
    {"globe", "right_refinement", "0",
     "globe-stereo, stereo:DIR: detect_both's right x taken from the left patch's correlation peak along the row "
     "within this many px of the right keypoint (ZNCC >= 0.9, no second peak >= 0.9; else the keypoint's x); 0: off",
     [](RunnerConfig& c, const std::string& v) { c.globe.right_refinement_px = parse_integer<int>(v, 0, 64); }},
    {"globe", "slanted_correlation", "false",
     "globe-stereo, stereo:DIR: each match's disparity re-measured within 4 px of its own by correlating the left "
     "patch with the right image warped by the disparity its neighbours' quadratic fit gives across the patch "
     "(ZNCC >= 0.9; else it keeps its own, or is dropped with unmeasured_disparities = drop)",
     [](RunnerConfig& c, const std::string& v) { c.globe.slanted_correlation = parse_bool(v); }},
    {"globe", "unmeasured_disparities", "keep",
     "globe-stereo, stereo:DIR, with slanted_correlation: keep (a match whose disparity the correlation does not "
     "measure keeps its own) | drop",
     [](RunnerConfig& c, const std::string& v) {
       c.globe.drop_unmeasured_disparities = one_of(v, {"keep", "drop"}, "unmeasured disparities") == "drop";
     }},
    {"globe", "disparity_sigma", "0",
     "globe-stereo, stereo:DIR: px, the image observations' disparity noise, independent of the left keypoint's "
     "(a disparity measured at the keypoint, slanted_correlation); 0: the right keypoint's own noise",
     [](RunnerConfig& c, const std::string& v) { c.globe.disparity_sigma = non_negative(parse_number(v), v); }},
    {"globe", "pipelined", "true",
     "globe-stereo, stereo:DIR: true (frame k+1's features found on a second thread while frame k is associated "
     "and filtered, as a live camera allows; the same results) | false (one frame after another)",
     [](RunnerConfig& c, const std::string& v) { c.globe.pipelined = parse_bool(v); }},
    {"globe", "opencv_threads", "1",
     "globe-stereo, stereo:DIR: OpenCV's worker threads inside AKAZE (0 = OpenCV's default, one per core); the "
     "pipeline and the two images on two threads keep the cores busy already",
     [](RunnerConfig& c, const std::string& v) { c.globe.opencv_threads = parse_integer<int>(v, 0, 256); }},
  };
}

/// [globe]: the globe's GraphSLAM runs.
inline std::vector<ConfigKey> globe_graph_keys() {
  return {
    {"globe", "graph_updates", "10", "GraphSLAM global updates after the windowed initialization (thesis Table 10: 10)",
     [](RunnerConfig& c, const std::string& v) { c.globe.graph_updates = parse_integer<int>(v, 1, 1e4); }},
    {"globe", "graph", "batch",
     "batch (the thesis's: record, then global updates) | online (one incremental Gauss-Newton step a frame, "
     "[graph] relinearize_threshold) | both (a row each)",
     [](RunnerConfig& c, const std::string& v) {
       one_of(v, {"batch", "online", "both"}, "GraphSLAM mode");
       c.globe.graph_batch = v != "online";
       c.globe.graph_online = v != "batch";
     }},
    {"globe", "graph_lag", "0",
     "the online row's fixed lag: one Gauss-Newton step a frame over the newest this many poses, older "
     "ones marginalized (a frame's cost bounded however long the tracks); 0 = the exact incremental smoother",
     [](RunnerConfig& c, const std::string& v) { c.globe.graph_lag = parse_integer<std::size_t>(v, 0, 1e6); }},
  };
}

/// [vislam]: the visual-inertial runs.
inline std::vector<ConfigKey> vislam_keys() {
  return {
    {"vislam", "velocity_sigma", "0.5", "m/s: IMU linear velocity noise per axis (.npz data)",
     [](RunnerConfig& c, const std::string& v) { c.vislam.velocity_sigma = positive(parse_number(v), v); }},
    {"vislam", "rate_sigma", "0.05", "rad/s: IMU angular velocity noise per axis (.npz data)",
     [](RunnerConfig& c, const std::string& v) { c.vislam.rate_sigma = positive(parse_number(v), v); }},
    {"vislam", "pixel_sigma", "2", "px: stereo feature noise (.npz data)",
     [](RunnerConfig& c, const std::string& v) { c.vislam.pixel_sigma = positive(parse_number(v), v); }},
    {"vislam", "min_disparity", "2", "px: smallest disparity a new landmark is triangulated from (.npz data)",
     [](RunnerConfig& c, const std::string& v) { c.vislam.min_disparity = non_negative(parse_number(v), v); }},
    {"vislam", "max_landmarks", "150", "landmark pool capacity (EKF: <= 10 ms per frame on 03.npz)",
     [](RunnerConfig& c, const std::string& v) { c.vislam.pool.max_landmarks = parse_integer<std::size_t>(v, 1, 1e6); }},
    {"vislam", "max_new_per_step", "20", "new landmarks per frame at most",
     [](RunnerConfig& c, const std::string& v) { c.vislam.pool.max_new_per_step = parse_integer<std::size_t>(v, 1, 1e6); }},
    {"vislam", "gate_probability", "0.999", "Mahalanobis gate of the filters (0 = off)",
     [](RunnerConfig& c, const std::string& v) { c.vislam.gate_probability = parse_gate_probability(v); }},
    {"vislam", "seed", "1", "simulation seed of stereo-vi",
     [](RunnerConfig& c, const std::string& v) { c.vislam.seed = parse_integer<std::uint64_t>(v, 0); }},
    {"vislam", "steps", "400", "stereo-vi frames (one loop)",
     [](RunnerConfig& c, const std::string& v) { c.vislam.steps = parse_integer<int>(v, 1, 1e6); }},
  };
}

/// [rawlog]: MRPT rawlogs and the sensor noise used with them.
inline std::vector<ConfigKey> rawlog_keys() {
  constexpr double deg = std::numbers::pi / 180.0;
  return {
    {"rawlog", "std_range", "0", "range noise, m; 0 = as stated in the rawlog",
     [](RunnerConfig& c, const std::string& v) {
       const double x = non_negative(parse_number(v), v);
       c.rawlog.std_range = x > 0.0 ? std::optional<double>(x) : std::nullopt;
     }},
    {"rawlog", "std_yaw_deg", "0", "bearing (yaw) noise, degrees; 0 = as stated in the rawlog",
     [](RunnerConfig& c, const std::string& v) {
       const double x = non_negative(parse_number(v), v);
       c.rawlog.std_yaw = x > 0.0 ? std::optional<double>(x * deg) : std::nullopt;
     }},
    {"rawlog", "std_pitch_deg", "0", "pitch noise (3D), degrees; 0 = as stated in the rawlog",
     [](RunnerConfig& c, const std::string& v) {
       const double x = non_negative(parse_number(v), v);
       c.rawlog.std_pitch = x > 0.0 ? std::optional<double>(x * deg) : std::nullopt;
     }},
    {"rawlog", "odometry_std_xy", "0.1", "observation-only rawlogs: odometry noise per step along x and y, m",
     [](RunnerConfig& c, const std::string& v) {
       c.rawlog.odometry_std(0) = c.rawlog.odometry_std(1) = positive(parse_number(v), v);
     }},
    {"rawlog", "odometry_std_phi_deg", "4", "observation-only rawlogs: odometry heading noise per step, degrees",
     [](RunnerConfig& c, const std::string& v) { c.rawlog.odometry_std(2) = positive(parse_number(v), v) * deg; }},
    {"rawlog", "at_rest_noise_scale", "0.001",
     "a step whose odometry increment is exactly zero is at rest: its stated noise times this (1 = as stated)",
     [](RunnerConfig& c, const std::string& v) { c.rawlog.at_rest_noise_scale = parse_fraction(v); }},
    {"rawlog", "prior_std", "1e-06", "standard deviation of the start pose (the robot starts at the map origin)",
     [](RunnerConfig& c, const std::string& v) { c.rawlog.prior_std = positive(parse_number(v), v); }},
    {"rawlog", "max_steps", "0", "read at most this many steps; 0 = all",
     [](RunnerConfig& c, const std::string& v) { c.rawlog.max_steps = parse_integer<std::size_t>(v, 0); }},
  };
}

/// [isam]: planar data sets in the iSAM/GTSAM text format (cityTrees10000, Victoria Park).
inline std::vector<ConfigKey> isam_keys() {
  return {
    {"isam", "filters_in_world_frame", "true",
     "iSAM text files: EKF and SEIF perturb the pose in the world frame (with first-estimate Jacobians: no spurious "
     "heading information); GraphSLAM and FastSLAM keep the additive chart",
     [](RunnerConfig& c, const std::string& v) { c.isam_filters_in_world_frame = parse_bool(v); }},
    {"isam", "graph_window", "1000",
     "iSAM text files: GraphSLAM's windowed initialization, steps (0 = off: from dead reckoning its Gauss-Newton ends in "
     "a twisted minimum on Victoria Park; 50-3000 reach the same optimum there); overrides [graph] window",
     [](RunnerConfig& c, const std::string& v) { c.isam_graph_window = parse_integer<std::size_t>(v, 0); }},
  };
}

/// [mrclam]: the UTIAS MRCLAM robots.
inline std::vector<ConfigKey> mrclam_keys() {
  constexpr double deg = std::numbers::pi / 180.0;
  return {
    {"mrclam", "max_step", "0.25", "MRCLAM: longest step without a measurement, s (steps also end at every measurement)",
     [](RunnerConfig& c, const std::string& v) { c.mrclam.max_step = positive(parse_number(v), v); }},
    {"mrclam", "odometry_delay", "0.2", "MRCLAM: seconds added to the odometry time stamps (Dataset6: 0.2 matches Vicon best)",
     [](RunnerConfig& c, const std::string& v) {
       const double d = parse_number(v);
       if (!(std::abs(d) <= 10.0)) throw invalid_input_error("'" + v + "' must be in [-10, 10] s");
       c.mrclam.odometry_delay = d;
     }},
    {"mrclam", "std_range", "0.15", "MRCLAM: range noise, m (robust SD against Vicon: 0.13)",
     [](RunnerConfig& c, const std::string& v) { c.mrclam.measurement_sigma(0) = positive(parse_number(v), v); }},
    {"mrclam", "std_bearing_deg", "1.146", "MRCLAM: bearing noise, degrees (robust SD against Vicon: 0.49)",
     [](RunnerConfig& c, const std::string& v) { c.mrclam.measurement_sigma(1) = positive(parse_number(v), v) * deg; }},
    {"mrclam", "alpha", "0.015 0.002 0.02 0.1 0 0.001",
     "MRCLAM: velocity motion model noise a1..a6 (Thrun): var v = a1 v^2 + a2 w^2, var w = a3 v^2 + a4 w^2, final "
     "turn a5 v^2 + a6 w^2",
     [](RunnerConfig& c, const std::string& v) {
       std::istringstream in(v);
       std::vector<double> values;
       for (std::string word; in >> word;) values.push_back(parse_number(word));
       if (values.size() != 6 || std::any_of(values.begin(), values.end(), [](double a) { return a < 0.0; }))
         throw invalid_input_error("'" + v + "' must be six non-negative numbers");
       std::copy(values.begin(), values.end(), c.mrclam.motion.alpha.begin());
     }},
    {"mrclam", "gate_probability", "0.9999",
     "MRCLAM: Mahalanobis gate of EKF and SEIF (real data has outliers; 0 = off); overrides their own (FastSLAM keeps [fastslam]'s)",
     [](RunnerConfig& c, const std::string& v) { c.mrclam_gate_probability = parse_gate_probability(v); }},
    {"mrclam", "reacquire_after_landmarks", "3",
     "MRCLAM: EKF and SEIF re-acquire a pose lost beyond their covariance (with the gate on; 0 = never); overrides "
     "[ekf] and [seif]",
     [](RunnerConfig& c, const std::string& v) { c.mrclam_reacquire_after_landmarks = parse_integer<int>(v, 0, 1e6); }},
    {"mrclam", "graph_robust_kernel", "cauchy", "MRCLAM: GraphSLAM's robust kernel (none | huber | cauchy); overrides [graph]",
     [](RunnerConfig& c, const std::string& v) {
       c.mrclam_graph_kernel = parse_choice<RobustKernel>(
           v, {{"none", RobustKernel::none}, {"huber", RobustKernel::huber}, {"cauchy", RobustKernel::cauchy}});
     }},
    {"mrclam", "filters_in_world_frame", "true",
     "MRCLAM: EKF and SEIF perturb the pose in the world frame (with the EKF's first-estimate Jacobians: no "
     "spurious heading information); GraphSLAM and FastSLAM keep the additive chart",
     [](RunnerConfig& c, const std::string& v) { c.mrclam_filters_in_world_frame = parse_bool(v); }},
  };
}

/// [association]: data association without known ids.
inline std::vector<ConfigKey> association_keys() {
  return {
    {"association", "method", "known",
     "known (the data set's ids) | nn (nearest neighbour) | jcbb (joint compatibility): ids withheld and found by "
     "EKF and SEIF; FastSLAM associates per particle; GraphSLAM needs known ids",
     [](RunnerConfig& c, const std::string& v) {
       c.association.method = parse_choice<std::optional<AssociationMethod>>(
           v, {{"known", std::nullopt},
               {"nn", AssociationMethod::nearest_neighbour},
               {"jcbb", AssociationMethod::joint_compatibility}});
     }},
    {"association", "gate_probability", "0.99", "chi-square gate of individual and joint compatibility",
     [](RunnerConfig& c, const std::string& v) { c.association.options.gate_probability = parse_probability(v); }},
    {"association", "new_landmark_probability", "0.9999",
     "a measurement outside every landmark's gate at this probability starts a new landmark; inside one but unpaired "
     "it is discarded",
     [](RunnerConfig& c, const std::string& v) { c.association.options.new_landmark_probability = parse_probability(v); }},
    {"association", "max_nodes", "20000",
     "JCBB: search nodes a step may visit before it settles for the best hypothesis found so far (the table counts "
     "the steps where it did)",
     [](RunnerConfig& c, const std::string& v) { c.association.options.max_nodes = parse_integer<std::size_t>(v, 1); }},
  };
}

/// [ekf]: EKF-SLAM's options.
inline std::vector<ConfigKey> ekf_keys() {
  return {
    {"ekf", "batch_update", "true", "one joint correction per step (true) or one per observation (false)",
     [](RunnerConfig& c, const std::string& v) { c.ekf.batch_update = parse_bool(v); }},
    {"ekf", "covariance_update", "symmetric", "symmetric (lower-triangle rank update) | joseph",
     [](RunnerConfig& c, const std::string& v) {
       c.ekf.covariance_update =
           parse_choice<CovarianceUpdate>(v, {{"symmetric", CovarianceUpdate::symmetric}, {"joseph", CovarianceUpdate::joseph}});
     }},
    {"ekf", "first_estimate_jacobians", "auto",
     "auto (on where the pose is perturbed in the world frame: MRCLAM) | true | false",
     [](RunnerConfig& c, const std::string& v) { c.ekf_first_estimates = parse_auto_switch(v); }},
    {"ekf", "observability_constraints", "auto",
     "auto (on where the state space names the world's rigid motions: the globe) | true | false: OC-EKF "
     "(docs/derivations/observability_constraints.md)",
     [](RunnerConfig& c, const std::string& v) { c.ekf_observability_constraints = parse_auto_switch(v); }},
    {"ekf", "gate_probability", "0", "Mahalanobis gate: reject observations above this chi-square quantile; 0 = off",
     [](RunnerConfig& c, const std::string& v) { c.ekf.gate_probability = parse_gate_probability(v); }},
    {"ekf", "reacquire_after_landmarks", "0",
     "with the gate on: rejected sightings of this many distinct landmarks, none accepted since, start the test "
     "of a lost pose (one offset explains them, dead reckoning could have drifted that far, the moved filter "
     "explains what follows: core/pose_reacquisition.hpp); 0 = keep rejecting",
     [](RunnerConfig& c, const std::string& v) { c.ekf.reacquisition.min_landmarks = parse_integer<int>(v, 0, 1e6); }},
    {"ekf", "reacquire_drift_factor", "5",
     "how many of its own standard deviations real odometry may drift beyond the motion model's dead reckoning",
     [](RunnerConfig& c, const std::string& v) { c.ekf.reacquisition.drift_factor = positive(parse_number(v), v); }},
    {"ekf", "reacquire_probation", "20", "sightings the moved copy and the filter are compared over",
     [](RunnerConfig& c, const std::string& v) { c.ekf.reacquisition.probation = parse_integer<int>(v, 1, 1e6); }},
    {"ekf", "tangent_reset", "false",
     "re-read P in the tangent at the corrected pose (G P G^T; SE(3) and world-frame SE(2) only): the error-state "
     "filter's reset, off because it fights first-estimate Jacobians (docs/derivations/state_space_jacobians.md)",
     [](RunnerConfig& c, const std::string& v) { c.ekf.tangent_reset = parse_bool(v); }},
    {"ekf", "iterations", "1",
     "linearizations per update, each at the previous one's correction (the iterated EKF; 1 = the textbook "
     "EKF): docs/results/iterated_ekf.md",
     [](RunnerConfig& c, const std::string& v) { c.ekf.iterations = parse_integer<int>(v, 1, 100); }},
  };
}

/// [seif]: SEIF-SLAM's options.
/// SEIF's chart, gate and re-acquisition (the keys before seif_keys()).
inline std::vector<ConfigKey> seif_robustness_keys() {
  return {
    {"seif", "first_estimate_jacobians", "auto",
     "auto (on where the pose is perturbed in the world frame: MRCLAM) | true | false",
     [](RunnerConfig& c, const std::string& v) { c.seif_first_estimates = parse_auto_switch(v); }},
    {"seif", "observability_constraints", "auto",
     "auto (on where the state space names the world's rigid motions: the globe) | true | false",
     [](RunnerConfig& c, const std::string& v) { c.seif_observability_constraints = parse_auto_switch(v); }},
    {"seif", "gate_probability", "0",
     "Mahalanobis gate with the exact marginals (one factorization per update); 0 = off",
     [](RunnerConfig& c, const std::string& v) { c.seif.gate_probability = parse_gate_probability(v); }},
    {"seif", "reacquire_after_landmarks", "0",
     "with the gate on: as [ekf] reacquire_after_landmarks, with the library's drift factor (5) and probation (20); "
     "0 = keep rejecting",
     [](RunnerConfig& c, const std::string& v) { c.seif.reacquisition.min_landmarks = parse_integer<int>(v, 0, 1e6); }},
  };
}

inline std::vector<ConfigKey> seif_keys() {
  return {
    {"seif", "max_active", "8", "landmarks kept linked to the robot by sparsification; 0 = no sparsification",
     [](RunnerConfig& c, const std::string& v) { c.seif.max_active = parse_integer<std::size_t>(v, 0, 1e6); }},
    {"seif", "sparsification", "thesis",
     "thesis (eqs. 37-44: drops the links, overconfident) | relocalization (ESEIF: marginalizes the robot and "
     "relocalizes it from held-back measurements, conservative; needs measurements that determine the robot "
     "state but for a tail the motion model declares unseen, such as the globe camera's velocities, which are "
     "relocalized with the prior's covariance; docs/results/seif_relocalization.md)",
     [](RunnerConfig& c, const std::string& v) {
       c.seif.sparsification = parse_choice<SeifSparsification>(
           v, {{"thesis", SeifSparsification::thesis}, {"relocalization", SeifSparsification::relocalization}});
     }},
    {"seif", "estimate", "auto",
     "auto (exact_mean with relocalization, recovered_mean with the thesis's sparsification) | recovered_mean (the "
     "update's, passive landmarks as they left the active set) | exact_mean (Omega^-1 xi, one more solve per query)",
     [](RunnerConfig& c, const std::string& v) {
       c.seif_estimate = v == "auto" ? std::nullopt
                                     : std::optional(parse_choice<SeifEstimate>(
                                           v, {{"recovered_mean", SeifEstimate::recovered_mean},
                                               {"exact_mean", SeifEstimate::exact_mean}}));
     }},
    {"seif", "iterations", "1",
     "linearizations per update, each at the mean the previous one recovered (the iterated SEIF; with "
     "relocalization the whole step iterates before the robot is relocalized; 1 = the thesis's SEIF): "
     "docs/results/iterated_ekf.md",
     [](RunnerConfig& c, const std::string& v) { c.seif.iterations = parse_integer<int>(v, 1, 100); }},
    {"seif", "relocalization_min_information", "0.05",
     "relocalization: share of the robot's information the held-back measurements must carry in every direction",
     [](RunnerConfig& c, const std::string& v) { c.seif.relocalization_min_information = non_negative(parse_number(v), v); }},
    {"seif", "relocalization_active_bound", "0",
     "relocalization: past this many active landmarks, held-back measurements that determine the pose at all relocalize it "
     "(a bounded step; the map pays: docs/results/seif_relocalization.md; 0 = no bound)",
     [](RunnerConfig& c, const std::string& v) { c.seif.relocalization_active_bound = parse_integer<std::size_t>(v, 0, 1e6); }},
    {"seif", "mean_recovery", "active_block", "active_block (joint solve) | coordinate_descent (thesis)",
     [](RunnerConfig& c, const std::string& v) {
       c.seif.mean_recovery = parse_choice<MeanRecovery>(
           v, {{"active_block", MeanRecovery::active_block}, {"coordinate_descent", MeanRecovery::coordinate_descent}});
     }},
    {"seif", "mean_recovery_sweeps", "1", "recovery sweeps per update",
     [](RunnerConfig& c, const std::string& v) { c.seif.mean_recovery_sweeps = parse_integer<int>(v, 0, 1e4); }},
    {"seif", "exact_recovery_period", "0", "every K updates an exact solve of the whole mean; 0 = never",
     [](RunnerConfig& c, const std::string& v) { c.seif.exact_recovery_period = parse_integer<int>(v, 0); }},
    {"seif", "stale_mean_probability", "auto",
     "the whole mean recovered exactly (one sparse solve) in a step after which a landmark next to the recovered "
     "block would move, given its neighbours, beyond the chi-square quantile at this probability of its "
     "conditional information, as after a loop closure; auto (0.999 with relocalization, 0 with the thesis's "
     "sparsification) | 0 = never | p",
     [](RunnerConfig& c, const std::string& v) {
       c.seif_stale_mean_probability = v == "auto" ? std::nullopt : std::optional(parse_gate_probability(v));
     }},
  };
}

/// [graph]: GraphSLAM's options.
inline std::vector<ConfigKey> graph_keys() {
  return {
    {"graph", "robust_kernel", "none", "none | huber | cauchy, on measurement factors",
     [](RunnerConfig& c, const std::string& v) {
       c.graph.measurement_loss.kernel = parse_choice<RobustKernel>(
           v, {{"none", RobustKernel::none}, {"huber", RobustKernel::huber}, {"cauchy", RobustKernel::cauchy}});
     }},
    {"graph", "kernel_width", "2.4477", "robust kernel width, standard deviations of the whitened residual",
     [](RunnerConfig& c, const std::string& v) { c.graph.measurement_loss.width = positive(parse_number(v), v); }},
    {"graph", "max_iterations", "100", "Gauss-Newton iterations at most (it stops earlier once converged)",
     [](RunnerConfig& c, const std::string& v) { c.graph.max_iterations = parse_integer<int>(v, 1, 1e6); }},
    {"graph", "solver", "automatic", "automatic | landmark_schur (thesis) | full (sparse Cholesky of everything)",
     [](RunnerConfig& c, const std::string& v) {
       c.graph.solver = parse_choice<GraphSolver>(v, {{"automatic", GraphSolver::automatic},
                                         {"landmark_schur", GraphSolver::landmark_schur},
                                         {"full", GraphSolver::full}});
     }},
    {"graph", "levenberg_marquardt", "false", "damp the Gauss-Newton steps",
     [](RunnerConfig& c, const std::string& v) { c.graph.levenberg_marquardt = parse_bool(v); }},
    {"graph", "damp_after_rise", "true", "Gauss-Newton: after an iteration whose cost rose, undo it and damp the steps after it",
     [](RunnerConfig& c, const std::string& v) { c.graph.damp_after_rise = parse_bool(v); }},
    {"graph", "window", "0", "windowed initialization: optimize growing parts of this many steps first; 0 = off",
     [](RunnerConfig& c, const std::string& v) { c.graph.window = parse_integer<std::size_t>(v, 0); }},
    {"graph", "reuse_retired_marginals", "false",
     "fixed lag: a landmark seen again after it left the window comes back with the marginal it left with as a "
     "prior (counts the closure twice: overconfident) | false: from the window's measurements alone",
     [](RunnerConfig& c, const std::string& v) { c.graph.reuse_retired_marginals = parse_bool(v); }},
    {"graph", "relinearize_threshold", "0.1",
     "online mode: relinearize a variable when its step exceeds this share of its standard deviation",
     [](RunnerConfig& c, const std::string& v) { c.graph.relinearize_threshold = positive(parse_number(v), v); }},
  };
}

/// [pose_graph]: the pose-graph runs.
inline std::vector<ConfigKey> pose_graph_keys() {
  return {
    {"pose_graph", "start", "file", "file (its vertices) | spanning_tree (of the odometry) | chordal (relaxation)",
     [](RunnerConfig& c, const std::string& v) {
       c.pose_graph_start = parse_choice<PoseGraphStart>(
           v, {{"file", PoseGraphStart::file}, {"spanning_tree", PoseGraphStart::spanning_tree}, {"chordal", PoseGraphStart::chordal}});
     }},
    {"pose_graph", "loop_closure_kernel", "none", "none | huber | cauchy, on edges between non-consecutive poses",
     [](RunnerConfig& c, const std::string& v) {
       c.pose_graph.loop_closure_loss.kernel = parse_choice<RobustKernel>(
           v, {{"none", RobustKernel::none}, {"huber", RobustKernel::huber}, {"cauchy", RobustKernel::cauchy}});
     }},
    {"pose_graph", "odometry_kernel", "none", "none | huber | cauchy, on edges between consecutive poses",
     [](RunnerConfig& c, const std::string& v) {
       c.pose_graph.odometry_loss.kernel = parse_choice<RobustKernel>(
           v, {{"none", RobustKernel::none}, {"huber", RobustKernel::huber}, {"cauchy", RobustKernel::cauchy}});
     }},
    {"pose_graph", "kernel_width", "2.4477", "robust kernel width, standard deviations of the whitened residual",
     [](RunnerConfig& c, const std::string& v) {
       c.pose_graph.loop_closure_loss.width = c.pose_graph.odometry_loss.width = positive(parse_number(v), v);
     }},
    {"pose_graph", "outlier_gate_probability", "0",
     "after the robust optimization, edges with a kernel beyond this chi-square quantile are dropped and the rest "
     "solved again by least squares; 0 = off (docs/results/pose_graphs.md: cauchy, width 1, 0.999)",
     [](RunnerConfig& c, const std::string& v) { c.pose_graph.outlier_gate_probability = parse_gate_probability(v); }},
    {"pose_graph", "max_iterations", "100", "Levenberg-Marquardt iterations at most",
     [](RunnerConfig& c, const std::string& v) { c.pose_graph.max_iterations = parse_integer<int>(v, 0, 1e6); }},
  };
}

/// [fastslam]: FastSLAM's options.
inline std::vector<ConfigKey> fastslam_keys() {
  return {
    {"fastslam", "gate_probability", "0", "Mahalanobis gate on known landmarks, against the particle cloud's predictive distribution; 0 = off",
     [](RunnerConfig& c, const std::string& v) { c.fastslam.gate_probability = parse_gate_probability(v); }},
    {"fastslam", "particles", "100", "particles",
     [](RunnerConfig& c, const std::string& v) { c.fastslam.particles = parse_integer<std::size_t>(v, 1, 1e6); }},
    {"fastslam", "resample_threshold", "0.1", "resample when N_eff < threshold * particles (1 = always, 0 = never)",
     [](RunnerConfig& c, const std::string& v) {
       const double t = parse_number(v);
       if (t < 0.0 || t > 1.0) throw invalid_input_error("'" + v + "' must be in [0, 1]");
       c.fastslam.resample_threshold = t;
     }},
    {"fastslam", "map_estimate", "weighted_average", "best_particle | weighted_average (moment-matched over particles)",
     [](RunnerConfig& c, const std::string& v) {
       c.fastslam.map_estimate =
           parse_choice<FastSlamMap>(v, {{"best_particle", FastSlamMap::best_particle}, {"weighted_average", FastSlamMap::weighted_average}});
     }},
    {"fastslam", "linear_tail", "sampled",
     "sampled | kalman: what particles do with state entries the motion model declares conditionally linear "
     "(the globe camera's velocity and rate): sample them, or keep a Kalman filter over them per particle",
     [](RunnerConfig& c, const std::string& v) {
       c.fastslam.linear_tail = parse_choice<FastSlamLinearTail>(
           v, {{"sampled", FastSlamLinearTail::sampled}, {"kalman", FastSlamLinearTail::kalman}});
     }},
    {"fastslam", "seed", "1", "random seed",
     [](RunnerConfig& c, const std::string& v) { c.fastslam.seed = parse_integer<std::uint64_t>(v, 0); }},
    {"fastslam", "iterations", "1",
     "linearizations of FastSLAM 2.0's proposal per update, each at the previous one's pose and landmarks (as "
     "[ekf] iterations; 1 = the textbook proposal): docs/results/iterated_ekf.md",
     [](RunnerConfig& c, const std::string& v) { c.fastslam.iterations = parse_integer<int>(v, 1, 100); }},
    {"fastslam", "estimate", "filter",
     "filter | path: score each step's pose as the step left it, or the path the particles hold at the end of the "
     "run (FastSLAM's path posterior, a smoother's trajectory as GraphSLAM's row scores)",
     [](RunnerConfig& c, const std::string& v) {
       c.fastslam.keep_paths = parse_choice<bool>(v, {{"filter", false}, {"path", true}});
     }},
    {"fastslam", "student_t_dof", "0",
     "the measurement noise as a Student-t of this many degrees of freedom (gross outliers): each update's noise "
     "scaled by (dof + NIS) / (dof + d), each weight the t density (0: Gaussian)",
     [](RunnerConfig& c, const std::string& v) { c.fastslam.student_t_dof = non_negative(parse_number(v), v); }},
  };
}

/// [scene]: the MRPT 3D scenes.
inline std::vector<ConfigKey> scene_keys() {
  return {
    {"scene", "quantile", "3", "size of the covariance ellipses in the .3Dscene, standard deviations",
     [](RunnerConfig& c, const std::string& v) { c.scene_quantile = positive(parse_number(v), v); }},
  };
}

}  // namespace detail

/// Every key sextant-run understands, in --print-config's order.
inline const std::vector<ConfigKey>& config_keys() {
  static const std::vector<ConfigKey> keys = [] {
    std::vector<ConfigKey> all;
    for (const auto& section : {detail::ship_keys(), detail::globe_keys(), detail::globe_stereo_keys(),
                                detail::globe_stereo_association_keys(), detail::globe_graph_keys(),
                                detail::vislam_keys(), detail::rawlog_keys(), detail::isam_keys(), detail::mrclam_keys(),
                                detail::association_keys(), detail::ekf_keys(), detail::seif_robustness_keys(),
                                detail::seif_keys(), detail::graph_keys(), detail::pose_graph_keys(), detail::fastslam_keys(),
                                detail::scene_keys()})
      all.insert(all.end(), section.begin(), section.end());
    return all;
  }();
  return keys;
}

/// The defaults as an ini file, every key with its meaning.
inline std::string documented_defaults() {
  std::ostringstream out;
  std::string section;
  for (const auto& k : config_keys()) {
    if (k.section != section) {
      out << (section.empty() ? "" : "\n") << "[" << k.section << "]\n";
      section = k.section;
    }
    out << "# " << k.meaning << "\n" << k.key << " = " << k.default_value << "\n";
  }
  return out.str();
}

namespace detail {

using io::printable_excerpt;

/// Reads the ini file line by line before MRPT's parser sees it, and throws "file:line: problem"
/// for what that parser would pass over in silence: a file it cannot read, bytes that are not text,
/// a line that is neither a comment, a [section], an MRPT directive (@...) nor key = value, a key
/// before any section, a key given twice in one section.
inline void lint_ini_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw invalid_input_error(path + ": cannot read the config file (" + std::strerror(errno) + ")");
  std::map<std::string, int> first_line;  // "[section] key" -> line
  std::string section, line;
  for (int number = 1; std::getline(in, line); ++number) {
    const std::string where = path + ":" + std::to_string(number) + ": ";
    for (unsigned char c : line)
      if ((c < 0x20 && c != '\t' && c != '\r') || c == 0x7f)
        throw invalid_input_error(where + "not a text line: '" + printable_excerpt(line) + "'");
    const std::string text = without_comment(line);
    if (text.empty() || text[0] == '#' || text[0] == ';' || text[0] == '@') continue;
    if (text.front() == '[') {
      if (text.back() != ']') throw invalid_input_error(where + "a section header without ']': '" + printable_excerpt(text) + "'");
      section = text.substr(1, text.size() - 2);
      continue;
    }
    const auto equals = text.find('=');
    if (equals == std::string::npos || equals == 0)
      throw invalid_input_error(where + "neither [section] nor key = value: '" + printable_excerpt(text) + "'");
    const std::string key = without_comment(text.substr(0, equals));
    if (section.empty()) throw invalid_input_error(where + key + ": a key before any [section]");
    const auto [it, fresh] = first_line.emplace("[" + section + "] " + key, number);
    if (!fresh)
      throw invalid_input_error(where + "[" + section + "] " + key + ": given twice (first at line " +
                                std::to_string(it->second) + ")");
  }
  if (in.bad()) throw invalid_input_error(path + ": cannot read the config file");
}

}  // namespace detail

/// The defaults, overridden by the file's keys; throws invalid_input_error "file: [section] key: problem"
/// (or "file:line: problem" for a line that is not a setting, detail::lint_ini_file).
inline RunnerConfig load_config(const std::string& path) {
  RunnerConfig config;
  for (const auto& k : config_keys()) k.apply(config, k.default_value);
  if (path.empty()) return config;
  if (!std::filesystem::is_regular_file(path)) throw invalid_input_error(path + ": cannot open config file (not a file)");
  detail::lint_ini_file(path);
  // MRPT's parser throws its own exceptions on what it cannot expand ("$env{" without its "}", a
  // broken "$eval{...}"): a file we cannot read is an invalid_input_error like any other.
  std::optional<::mrpt::config::CConfigFile> parsed;
  std::vector<std::string> sections;
  try {
    parsed.emplace(path);
    parsed->getAllSections(sections);
  } catch (const std::exception& e) {
    throw invalid_input_error(path + ": not a readable ini file (" +
                              detail::printable_excerpt(mrpt_io::exception_message(e.what()), 300) + ")");
  }
  auto& file = *parsed;
  for (const auto& section : sections) {
    std::vector<std::string> names;
    file.getAllKeys(section, names);
    for (const auto& name : names) {
      const auto it = std::find_if(config_keys().begin(), config_keys().end(),
                                   [&](const ConfigKey& k) { return k.section == section && k.key == name; });
      const std::string where = path + ": [" + section + "] " + name;
      if (it == config_keys().end()) throw invalid_input_error(where + ": unknown key (see sextant-run --print-config)");
      try {
        it->apply(config, detail::without_comment(file.read_string(section, name, "", true)));
      } catch (const std::exception& e) {
        throw invalid_input_error(where + ": " + detail::printable_excerpt(e.what(), 300));
      }
    }
  }
  return config;
}

}  // namespace sextant::runner
