// sextant-globe-stereo's runs (issue 12): the globe rendered as a rectified stereo sequence
// (--dataset globe-stereo) or a user's rectified stereo sequence (--dataset stereo:<dir>), through the
// OpenCV front-end (AKAZE or ORB, row matching, triangulation, association gated by the EKF's prediction,
// the landmark pool) and then every back-end on the observations it produced.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sextant/backends/ekf_slam.hpp>
#include <sextant/backends/seif_slam.hpp>
#include <sextant/io/csv_writer.hpp>
#include <sextant/io/tum_writer.hpp>
#include <sextant/sim/globe_render.hpp>
#include <sextant/eval/globe_association_truth.hpp>
#include <sextant/vision/globe_calibration.hpp>
#include <sextant/vision/gray_image_view.hpp>
#include <sextant/vision/opencv_threads.hpp>
#include <sextant/vision/stereo_sequence.hpp>
#include <sextant/vision/stereo_sequence_tracking.hpp>
#include <sextant/vision/stereo_tracker.hpp>
#include <string>
#include <vector>

#include "backend_factory.hpp"
#include "globe_runs.hpp"
#include "dataset_registry.hpp"
#include "progress_bar.hpp"
#include "runner_config.hpp"
#include "table.hpp"

namespace sextant::runner {
namespace {

using Observations = std::vector<Observation<Eigen::Vector3d>>;

/// Sums over the frames of a run: the front-end's figures and the time per stage.
struct FrontEndTotals {
  std::size_t frames = 0, left_keypoints = 0, stereo_matches = 0, observations = 0, associated = 0, created = 0;
  std::size_t returned = 0;  ///< of the associated: returning landmarks ([globe] returning_after)
  std::size_t below_min_disparity = 0, without_support = 0, right_refined = 0, slant_refined = 0, slant_unmeasured = 0;
  double min_disparity = 0.0;  ///< px, the front-end's floor
  vision::TrackerTimes times;
  double render = 0.0;

  void add(const vision::TrackedFrame& f) {
    ++frames;
    left_keypoints += f.left_keypoints;
    stereo_matches += f.stereo_matches;
    below_min_disparity += f.below_min_disparity;
    without_support += f.without_support;
    right_refined += f.right_refined;
    slant_refined += f.slant_refined;
    slant_unmeasured += f.slant_unmeasured;
    observations += f.observations.size();
    for (bool is_new : f.is_new) ++(is_new ? created : associated);
    returned += f.returned;
    times.detect += f.times.detect;
    times.match += f.times.match;
    times.triangulate += f.times.triangulate;
    times.associate += f.times.associate;
    times.backend += f.times.backend;
  }
};

void print_front_end(const FrontEndTotals& t, const vision::SequenceClock& clock, const GlobeSettings& settings,
                     const eval::GlobeAssociationTruth* truth, const std::string& tracker) {
  const double n = static_cast<double>(std::max<std::size_t>(t.frames, 1));
  std::printf("front-end over %zu frames: %.0f left keypoints, %.0f stereo matches, %.1f observations per frame "
              "(%.1f associated, %.1f proposed as new)",
              t.frames, t.left_keypoints / n, t.stereo_matches / n, t.observations / n, t.associated / n, t.created / n);
  if (settings.returning_after > 0)
    std::printf("; %zu associations in all of returning landmarks (unseen for %zu frames or more)", t.returned,
                settings.returning_after);
  if (t.min_disparity > 0)
    std::printf("; %zu stereo matches in all dropped below the disparity floor (%.2f px, %g standard deviations)",
                t.below_min_disparity, t.min_disparity, settings.min_disparity_sigmas);
  if (settings.disparity_support)
    std::printf("; %zu dropped for want of support from their neighbours' disparities", t.without_support);
  if (settings.right_refinement_px > 0)
    std::printf("; %.1f right x a frame moved to the correlation peak within %d px", t.right_refined / n,
                settings.right_refinement_px);
  if (settings.slanted_correlation)
    std::printf("; %.1f disparities a frame measured along the slant (%zu unmeasured matches dropped in all)",
                t.slant_refined / n, t.slant_unmeasured);
  if (truth)
    std::printf("; association precision %.4f (%zu of %zu right against the rendering)", truth->precision(),
                truth->right(), truth->associated());
  if (truth)
    std::printf("; %zu of %zu new landmarks from wrong stereo matches against the rendering",
                truth->new_from_wrong_matches(), truth->created());
  if (truth)
    std::printf("; the right re-observations against the rendering under their stated noise: NIS mean %.2f, median %.2f, "
                "%.1f%% inside 7.81 (3 dof), left keypoint %.2f px RMS from the true point",
                truth->mean_nis(), truth->median_nis(), 100 * truth->share_of_nis_within(7.81), truth->pixel_rms());
  std::printf("\n%-12s %9s %9s %11s %10s %12s %9s %11s %10s\n", "ms/frame", "detect", "match", "triangulate",
              "associate", (tracker + " back-end").c_str(), "stages", "wall clock", "frames/s");
  const auto& s = t.times;
  std::printf("%-12s %9.2f %9.2f %11.3f %10.2f %12.2f %9.2f %11.2f %10.2f\n", "", 1e3 * s.detect / n,
              1e3 * s.match / n, 1e3 * s.triangulate / n, 1e3 * s.associate / n, 1e3 * s.backend / n,
              1e3 * s.total() / n, 1e3 * clock.seconds / n, clock.frames_per_second());
  std::printf("(%s; [globe] pipelined = %s, opencv_threads = %d)\n",
              settings.pipelined ? "pipelined: frame k+1's detect, match and triangulate on a second thread while "
                                   "frame k is associated and filtered, so the stages overlap and share the cores"
                                 : "one frame after another",
              settings.pipelined ? "true" : "false", settings.opencv_threads);
  if (t.render > 0.0) std::printf("(rendering, not part of the pipeline: %.1f ms per stereo pair)\n", 1e3 * t.render / n);
}

/// Every observation the front-end handed to the pool, one row each (the round-trip test compares these files).
void write_observations(const std::filesystem::path& dir, const std::vector<Observations>& frames,
                        const std::vector<std::vector<bool>>& is_new) {
  std::filesystem::create_directories(dir);
  io::CsvWriter csv((dir / "observations.csv").string(), {"step", "id", "x", "y", "z", "new"});
  for (std::size_t k = 0; k < frames.size(); ++k)
    for (std::size_t i = 0; i < frames[k].size(); ++i) {
      const auto& o = frames[k][i];
      csv.row({static_cast<double>(k), static_cast<double>(o.landmark_id), o.z.x(), o.z.y(),
               o.z.z(), is_new[k][i] ? 1.0 : 0.0});
    }
}

/// The README's picture: one rendered pair with the features the front-end handed on (green:
/// associated with the map, orange: proposed as new) joined left to right; below, the tracker's map and
/// trajectories seen from above (x-z) and from the side (x-y), the truth in white, the estimate in red.
struct PictureFrame {
  cv::Mat left, right;
  vision::TrackedFrame tracked;
};

void draw_pipeline_picture(const std::filesystem::path& file, const PictureFrame& f, const std::vector<LandmarkEstimate<3>>& map,
                           const std::vector<Vector12d>& truth, const std::vector<Vector12d>& estimate,
                           const std::string& tracker) {
  const int w = f.left.cols, h = f.left.rows;
  cv::Mat canvas(2 * h, 2 * w, CV_8UC3, cv::Scalar(30, 30, 30));
  cv::cvtColor(f.left, canvas(cv::Rect(0, 0, w, h)), cv::COLOR_GRAY2BGR);
  cv::cvtColor(f.right, canvas(cv::Rect(w, 0, w, h)), cv::COLOR_GRAY2BGR);
  for (std::size_t i = 0; i < f.tracked.observed.size(); ++i) {
    const auto& o = f.tracked.observed[i];
    const cv::Scalar colour = f.tracked.is_new[i] ? cv::Scalar(0, 165, 255) : cv::Scalar(0, 220, 0);
    const cv::Point l(static_cast<int>(o.left_px.x()), static_cast<int>(o.left_px.y()));
    const cv::Point r(w + static_cast<int>(o.right_px.x()), static_cast<int>(o.right_px.y()));
    cv::circle(canvas, l, 4, colour, 1, cv::LINE_AA);
    cv::circle(canvas, r, 4, colour, 1, cv::LINE_AA);
    cv::line(canvas, l, r, colour, 1, cv::LINE_AA);
  }
  const double scale = 0.85 * h;  // px per m: the orbit (0.45 m radius) fills the panel
  auto panel = [&](int x0, int a, int b, const char* title) {
    const cv::Point centre(x0 + w / 2, h + h / 2);
    auto at = [&](const Eigen::Vector3d& p) {
      return cv::Point(centre.x + static_cast<int>(scale * p(a)), centre.y + static_cast<int>(scale * p(b)));
    };
    for (const auto& l : map) cv::circle(canvas, at(l.mean), 1, cv::Scalar(255, 180, 60), cv::FILLED);
    auto path = [&](const std::vector<Vector12d>& poses, const cv::Scalar& colour, int thickness = 1) {
      for (std::size_t k = 1; k < poses.size(); ++k)
        cv::line(canvas, at(poses[k - 1].head<3>()), at(poses[k].head<3>()), colour, thickness, cv::LINE_AA);
    };
    path(truth, cv::Scalar(255, 255, 255), 3);
    path(estimate, cv::Scalar(60, 60, 255));
    cv::putText(canvas, title, cv::Point(x0 + 10, h + 25), cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(230, 230, 230), 1,
                cv::LINE_AA);
  };
  panel(0, 0, 2, ("from above (x-z): " + tracker + " map (blue), true path (white), " + tracker + " path (red)").c_str());
  panel(w, 0, 1, "from the side (x-y)");
  cv::putText(canvas, "left", cv::Point(10, 25), cv::FONT_HERSHEY_SIMPLEX, 0.6, cv::Scalar(230, 230, 230), 1, cv::LINE_AA);
  cv::putText(canvas, "right: green associated, orange new", cv::Point(w + 10, 25), cv::FONT_HERSHEY_SIMPLEX, 0.6,
              cv::Scalar(230, 230, 230), 1, cv::LINE_AA);
  if (!cv::imwrite(file.string(), canvas)) throw invalid_input_error(file.string() + ": cannot be written");
}

/// The tracker's settings from [globe]; the disparity floor in standard deviations of the sensor's
/// pixel noise, which is also the disparity support test's least scatter about a plane.
vision::StereoTrackerOptions tracker_options(const RunnerConfig& c, const PointInCamera3D& sensor) {
  vision::StereoTrackerOptions o;
  o.front_end.min_disparity = vision::significant_disparity(sensor.noise.pixel_sigma, c.globe.min_disparity_sigmas);
  o.front_end.slant_noise = c.globe.slant_noise;
  o.front_end.disparity_support = c.globe.disparity_support;
  o.front_end.support.min_sigma_px = vision::significant_disparity(sensor.noise.pixel_sigma, 1.0);
  o.pool = c.globe.pool;
  o.association.max_observations = static_cast<std::size_t>(c.globe.features_per_frame);
  o.association.new_landmark_density = c.globe.new_landmark_density;
  o.association.student_t_dof = c.globe.student_t_dof;
  o.returning.after_frames = c.globe.returning_after;
  o.returning.window = c.globe.returning_window;
  o.front_end.detector.octave_layers = c.globe.octave_layers;
  o.front_end.detector.threshold = static_cast<float>(c.globe.detector_threshold);
  if (c.globe.orb) o.front_end.detector.detector = vision::Detector::orb;
  o.front_end.detector.orb_levels = c.globe.orb_levels;
  if (c.globe.row_search) o.front_end.correspondence = vision::StereoCorrespondence::row_search;
  o.front_end.right_refinement.radius = c.globe.right_refinement_px;
  o.front_end.slanted_correlation = c.globe.slanted_correlation;
  o.front_end.slanted.drop_unmeasured = c.globe.drop_unmeasured_disparities;
  o.gate_covariance = c.globe.tracker_exact_gate ? vision::GateCovariance::joint_marginal : vision::GateCovariance::conditional;
  return o;
}

/// Calls `run(tracker, name)` with the stereo tracker of [globe] tracker: the EKF, SEIF with the
/// first [globe] seif_active value, or ESEIF (relocalizing) with the first eseif_active value, each
/// configured as the table's run of that back-end is (backend_choices: [ekf] and [seif] with the
/// 12D camera's observability constraints where the config leaves them automatic).
template <class Run>
auto with_tracker(const RunnerConfig& c, const EulerCamera12D& motion, const PointInCamera3D& sensor,
                  const Gaussian<Vector12d, 12>& prior, const vision::StereoRig& rig, int width, int height, Run&& run) {
  const BackendChoice choice = backend_choices<EulerCamera12D>({c.globe.tracker}, c).front();
  if (c.globe.tracker == BackendKind::seif || c.globe.tracker == BackendKind::eseif) {
    const bool relocalizing = c.globe.tracker == BackendKind::eseif;
    const auto& active = relocalizing ? c.globe.eseif_active : c.globe.seif_active;
    const std::string key = relocalizing ? "eseif" : "seif";
    if (active.empty()) throw invalid_input_error("[globe] tracker = " + key + " needs a [globe] " + key + "_active value");
    SeifOptions seif = choice.seif;
    seif.max_active = active.front();
    vision::StereoTracker<SeifSlam<EulerCamera12D, PointInCamera3D>> tracker(
        {motion, sensor, prior, seif}, sensor, rig, width, height, tracker_options(c, sensor));
    return run(tracker, std::string(seif.sparsification == SeifSparsification::relocalization ? "ESEIF" : "SEIF"));
  }
  vision::StereoTracker<EkfSlam<EulerCamera12D, PointInCamera3D>> tracker({motion, sensor, prior, choice.ekf}, sensor,
                                                                           rig, width, height, tracker_options(c, sensor));
  return run(tracker, std::string("EKF"));
}

/// The sequence through the tracker as [globe] pipelined and opencv_threads say (vision::track_sequence).
template <class Tracker, class PairOf, class DtOf, class OnFrame>
vision::SequenceClock track_frames(Tracker& tracker, std::size_t n, PairOf&& pair_of, DtOf&& dt_of, OnFrame&& on_frame,
                                   const RunnerConfig& config) {
  const vision::OpenCvThreads threads(config.globe.opencv_threads);
  return vision::track_sequence(tracker, n, pair_of, dt_of, on_frame, config.globe.pipelined);
}

/// The globe rendered as stereo images, the front-end, then every back-end on its observations and,
/// for comparison, the EKF on the point simulator's observations of the same trajectory; with
/// --save-images the rendered sequence is also written there (stereo:<dir> layout).
std::vector<TableRow> run_globe_stereo(const CliOptions& cli, const std::string&, const std::vector<BackendKind>& kinds,
                                       const RunnerConfig& config) {
  const RunOptions& options = cli.output;
  const std::string& save_images = cli.save_images;
  const auto o = globe_options(config.globe);
  const auto points = sim::simulate_globe_camera(o);
  std::printf("\n== globe-stereo: the globe of --dataset globe rendered as %dx%d stereo pairs (seed %llu, texture seed %llu), "
              "%d frames through the %s front-end; pool Mmax = %zu, max_new = %zu, %d observations per frame at most\n",
              o.image_width, o.image_height, static_cast<unsigned long long>(o.seed),
              static_cast<unsigned long long>(config.globe.texture_seed), o.num_steps,
              config.globe.orb ? "ORB" : "AKAZE", config.globe.pool.max_landmarks, config.globe.pool.max_new_per_step,
              config.globe.features_per_frame);
  const auto calibration = vision::globe_calibration(o, points.prior);
  if (!save_images.empty()) vision::write_calibration(save_images, calibration);
  PointInCamera3D image_sensor = points.sensor;  // the observations' noise as the front-end measures them
  image_sensor.noise.disparity_sigma = config.globe.disparity_sigma;
  return with_tracker(config, points.motion, image_sensor, points.prior, calibration.rig(), o.image_width, o.image_height,
                      [&](auto& tracker, const std::string& tracker_name) {
    eval::GlobeAssociationTruth truth(o);
    FrontEndTotals totals;
    totals.min_disparity = tracker.front_end().options().min_disparity;
    sim::GlobeCameraDataset stereo = points;
    stereo.sensor = image_sensor;
    std::vector<Observations> frames;
    std::vector<std::vector<bool>> is_new;
    std::vector<Vector12d> tracked_means;
    PictureFrame picture;
    const std::size_t picture_step = std::min<std::size_t>(100, points.steps.size() - 1);
    ProgressBar progress("globe-stereo: render + front-end", points.steps.size());
    auto render = [&](std::size_t k) {
      const auto start = std::chrono::steady_clock::now();
      const auto images = sim::render_stereo(o, points.true_poses[k + 1], {.texture_seed = config.globe.texture_seed});
      totals.render += seconds_since(start);
      vision::StereoPair pair{vision::as_mat(images.left).clone(), vision::as_mat(images.right).clone()};
      if (!save_images.empty()) vision::write_stereo_pair(save_images, k, pair.left, pair.right);
      if (k == picture_step) picture.left = pair.left, picture.right = pair.right;
      return pair;
    };
    auto record = [&](std::size_t k, const vision::TrackedFrame& tracked) {
      truth.score(points.true_poses[k + 1], tracked);
      totals.add(tracked);
      stereo.steps[k].observations = tracked.observations;
      frames.push_back(tracked.observations);
      is_new.push_back(tracked.is_new);
      tracked_means.push_back(pose_mean_of(tracker.backend()));
      if (k == picture_step) picture.tracked = tracked;
      progress.advance();
    };
    const auto clock = track_frames(tracker, points.steps.size(), render,
                                    [&](std::size_t k) { return points.steps[k].dt; }, record, config);
    stereo.true_landmarks = truth.true_landmarks();
    print_front_end(totals, clock, config.globe, &truth, tracker_name);
    if (!save_images.empty()) std::printf("wrote the rendered sequence to %s (left/, right/, calib.yaml)\n", save_images.c_str());
    if (!options.out.empty()) write_observations(std::filesystem::path(options.out) / "globe-stereo", frames, is_new);
    if (options.plots) {
      const auto file = std::filesystem::path(options.out) / "globe-stereo" / "pipeline.png";
      const std::vector<Vector12d> truth_path(points.true_poses.begin() + 1, points.true_poses.end());
      draw_pipeline_picture(file, picture, tracker.backend().map(), truth_path, tracked_means, tracker_name);
      std::printf("wrote %s (frame %zu with its features, the %s's map and trajectory)\n", file.c_str(), picture_step,
                  tracker_name.c_str());
    }
    std::printf("\nevery back-end on the front-end's observations:\n");
    auto rows = run_globe_dataset(options, "globe-stereo", stereo, kinds, config);
    std::printf("\nfor comparison, the point simulator (--dataset globe) on the same trajectory, EKF:\n");
    const auto reference = run_globe_dataset(options, "globe", points, {BackendKind::ekf}, config);
    rows.insert(rows.end(), reference.begin(), reference.end());
    print_start_draw(stereo);
    return rows;
  });
}

/// A user's rectified sequence (left/*.png, right/*.png, calib.yaml): the front-end with EKF tracking.
std::vector<TableRow> run_stereo_directory(const CliOptions& cli, const std::string& dataset,
                                           const std::vector<BackendKind>&, const RunnerConfig& config) {
  const RunOptions& options = cli.output;
  const std::string dir = dataset.substr(std::string("stereo:").size());
  const vision::StereoSequence sequence(dir);
  const auto& c = sequence.calibration();
  PointInCamera3D sensor;
  sensor.noise.focal_px = c.K(0, 0);
  sensor.noise.baseline = c.baseline;
  sensor.noise.disparity_sigma = config.globe.disparity_sigma;
  const auto prior = vision::initial_camera_estimate(c);
  return with_tracker(config, EulerCamera12D{}, sensor, prior, c.rig(), c.width, c.height,
                      [&](auto& tracker, const std::string& tracker_name) {
    std::printf("\n== stereo:%s: %zu rectified pairs, %dx%d, f = %.1f px, baseline %.3f m, dt %.4f s; %s tracking\n",
                dir.c_str(), sequence.size(), c.width, c.height, c.K(0, 0), c.baseline, c.dt, tracker_name.c_str());
    FrontEndTotals totals;
    totals.min_disparity = tracker.front_end().options().min_disparity;
    std::vector<Observations> frames;
    std::vector<std::vector<bool>> is_new;
    std::vector<io::TumPose> trajectory;
    ProgressBar progress("stereo: front-end", sequence.size());
    auto load = [&](std::size_t k) {
      auto [left, right] = sequence.load(k);
      return vision::StereoPair{std::move(left), std::move(right)};
    };
    auto record = [&](std::size_t k, const vision::TrackedFrame& tracked) {
      totals.add(tracked);
      frames.push_back(tracked.observations);
      is_new.push_back(tracked.is_new);
      const Vector12d x = pose_mean_of(tracker.backend());
      trajectory.push_back({c.dt * static_cast<double>(k + 1), x.head<3>(), Eigen::Quaterniond(euler_yxz::rotation(x.segment<3>(3)))});
      progress.advance();
    };
    const auto clock = track_frames(tracker, sequence.size(), load, [&](std::size_t) { return c.dt; }, record, config);
    print_front_end(totals, clock, config.globe, nullptr, tracker_name);
    std::printf("%s at the end: %zu landmarks in the map; no ground truth with a stereo directory, so no error columns\n",
                tracker_name.c_str(), tracker.backend().landmark_ids().size());
    if (!options.out.empty()) {
      const auto out = std::filesystem::path(options.out) / "stereo";
      write_observations(out, frames, is_new);
      const std::string file = backend_key(config.globe.tracker) + "_trajectory.tum";
      io::write_tum((out / file).string(), trajectory);
      std::printf("wrote observations.csv and %s to %s\n", file.c_str(), out.c_str());
    }
    return std::vector<TableRow>{};
  });
}

const RegisterDatasetRun rendered_registration{"globe-stereo", run_globe_stereo};
const RegisterDatasetRun directory_registration{"stereo", run_stereo_directory};

}  // namespace
}  // namespace sextant::runner
