// The stereo front-end on the rendered globe (sim/globe_render.hpp): KAZE features matched left to
// right along the rows, scored against the rendering's ground truth, and triangulated.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numeric>
#include <optional>
#include <tuple>
#include <opencv2/core.hpp>
#include <vector>

#include "sextant/sim/globe_render.hpp"
#include "sextant/vision/features.hpp"
#include "sextant/vision/globe_calibration.hpp"
#include "sextant/vision/gray_image_view.hpp"
#include "sextant/vision/row_search_matching.hpp"
#include "sextant/vision/slanted_correlation.hpp"
#include "sextant/vision/stereo_front_end.hpp"
#include "sextant/vision/stereo_matching.hpp"
#include "sextant/vision/stereo_triangulation.hpp"

namespace sextant::vision {
namespace {

struct RenderedPair {
  sim::GlobeCameraOptions options;
  Vector12d pose;
  StereoRig rig = globe_rig(options);
  sim::StereoImages images;

  explicit RenderedPair(const Vector12d& x) : pose(x), images(sim::render_stereo(options, pose)) {}
  RenderedPair() : RenderedPair(sim::detail::orbit_start(sim::GlobeCameraOptions{})) {}

  Eigen::Vector3d in_camera(const Eigen::Vector3d& world) const { return sim::in_left_camera(pose, world); }
  /// The true point in the left camera frame behind a left pixel, if the pixel shows the globe.
  std::optional<Eigen::Vector3d> true_point(const Eigen::Vector2d& left_px) const {
    const auto m = sim::surface_point(options, pose, left_px.x(), left_px.y());
    if (!m) return std::nullopt;
    return in_camera(*m);
  }
  /// The rendering's answer key (sim::stereo_match_is_right).
  bool is_right(const StereoMatch& m, float left_size) const {
    return sim::stereo_match_is_right(options, pose, m.left_px, m.right_px, left_size);
  }
};

TEST(StereoFrontEnd, StereoMatchesAlongTheOrbitAreRightAgainstTheRenderingsTruth) {
  const sim::GlobeCameraOptions options;
  const auto orbit = sim::simulate_globe_camera(options).true_poses;
  // ORB as camera_rate.ini runs it: every corner at full resolution
  for (const DetectorOptions detector_options :
       {DetectorOptions{.detector = Detector::akaze}, DetectorOptions{.detector = Detector::kaze},
        DetectorOptions{.detector = Detector::orb, .orb_levels = 1}}) {
    const Detector kind = detector_options.detector;
    auto detector = make_detector(detector_options);
    std::size_t matches = 0, right = 0, fewest = std::numeric_limits<std::size_t>::max();
    for (const std::size_t step : {0, 100, 200, 300, 400}) {
      const RenderedPair pair(orbit[step]);
      const auto left = detect(as_mat(pair.images.left), *detector);
      const auto found = match_stereo(left, detect(as_mat(pair.images.right), *detector));
      fewest = std::min(fewest, found.size());
      matches += found.size();
      for (const auto& m : found) right += pair.is_right(m, left.keypoints[static_cast<std::size_t>(m.left)].size);
    }
    const double precision = static_cast<double>(right) / static_cast<double>(matches);
    std::printf("%s: %zu stereo matches over 5 frames (fewest in a frame %zu), %zu right: precision %.4f\n",
                kind == Detector::akaze ? "AKAZE" : kind == Detector::orb ? "ORB (one level)" : "KAZE (upright)", matches,
                fewest, right, precision);
    // Enough for the thesis's frames (it kept the 120 strongest features per frame) ...
    EXPECT_GE(fewest, 120u);
    // ... and, for the default detector and the camera-rate one, right at issue 12's association precision (>= 99%).
    if (kind != Detector::kaze) {
      EXPECT_GE(precision, 0.99);
    }
  }
}

TEST(StereoFrontEnd, TriangulatedPointsLieOnTheGlobe) {
  const RenderedPair pair;
  auto detector = make_detector({});
  const auto left = detect(as_mat(pair.images.left), *detector);
  const auto matches = match_stereo(left, detect(as_mat(pair.images.right), *detector));
  ASSERT_FALSE(matches.empty());
  std::vector<double> depth_errors;
  for (const auto& m : matches) {
    const auto truth = pair.true_point(m.left_px);
    if (!truth || !pair.is_right(m, left.keypoints[static_cast<std::size_t>(m.left)].size)) continue;
    const Eigen::Vector3d q = triangulate(pair.rig, m);
    // x and y follow the left pixel's ray exactly: the error is along the ray (the depth)
    EXPECT_NEAR(q.x() / q.z(), truth->x() / truth->z(), 1e-9);
    EXPECT_NEAR(q.y() / q.z(), truth->y() / truth->z(), 1e-9);
    depth_errors.push_back(std::abs(q.z() - truth->z()));
  }
  std::sort(depth_errors.begin(), depth_errors.end());
  const double median = depth_errors[depth_errors.size() / 2];
  // At ~0.45 m a disparity error of 1 px moves the depth by z^2 / (f b) = 3.4 mm.
  const double one_pixel = 0.45 * 0.45 / (pair.rig.focal_px * pair.rig.baseline);
  std::printf("median |depth error| %.2f mm (one pixel of disparity: %.2f mm)\n", 1e3 * median, 1e3 * one_pixel);
  EXPECT_LT(median, one_pixel);
}

/// Row search (no right detection) against descriptor matching of features detected in both images,
/// on the same left keypoints along the orbit: issue 12's precision (>= 99% right against the
/// rendering), enough matches for the thesis's 120 a frame, and depth at least as accurate as the
/// descriptor matches' (median |depth error| of the right matches, the peer computed here).
TEST(StereoFrontEnd, RowSearchMatchesAreRightAndTheirDepthAsGoodAsDetectingBothImages) {
  const sim::GlobeCameraOptions options;
  const auto orbit = sim::simulate_globe_camera(options).true_poses;
  auto detector = make_detector({});
  std::size_t searched = 0, searched_right = 0, fewest = std::numeric_limits<std::size_t>::max();
  std::vector<double> search_depth, detect_depth;
  auto depth_error = [](const RenderedPair& pair, const StereoMatch& m) {
    const auto truth = pair.true_point(m.left_px);
    return truth ? std::optional(std::abs(triangulate(pair.rig, m).z() - truth->z())) : std::nullopt;
  };
  for (const std::size_t step : {0, 100, 200, 300, 400}) {
    const RenderedPair pair(orbit[step]);
    const auto left = detect(as_mat(pair.images.left), *detector);
    const auto found = search_rows(as_mat(pair.images.left), as_mat(pair.images.right), left);
    fewest = std::min(fewest, found.size());
    searched += found.size();
    for (const auto& m : found) {
      EXPECT_EQ(m.right, -1);
      EXPECT_EQ(m.right_px.y(), m.left_px.y());
      const bool right = pair.is_right(m, left.keypoints[static_cast<std::size_t>(m.left)].size);
      searched_right += right;
      if (const auto e = depth_error(pair, m); right && e) search_depth.push_back(*e);
    }
    for (const auto& m : match_stereo(left, detect(as_mat(pair.images.right), *detector)))
      if (const auto e = depth_error(pair, m); e && pair.is_right(m, left.keypoints[static_cast<std::size_t>(m.left)].size))
        detect_depth.push_back(*e);
  }
  const double precision = static_cast<double>(searched_right) / static_cast<double>(searched);
  auto median = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
  };
  std::printf("row search: %zu matches over 5 frames (fewest %zu), precision %.4f, median |depth error| %.3f mm; "
              "detecting both: %.3f mm\n",
              searched, fewest, precision, 1e3 * median(search_depth), 1e3 * median(detect_depth));
  EXPECT_GE(fewest, 120u);
  EXPECT_GE(precision, 0.99);
  EXPECT_LE(median(search_depth), median(detect_depth));
}

/// detect_both's right x by correlation (FrontEndOptions::right_refinement) against the right
/// keypoint's own x, on the same descriptor matches along the orbit: the disparity error against the
/// rendering's truth is smaller (median and share beyond a pixel; the peer is the unrefined match in
/// the same loop), no left pixel or row moves, a right x moves at most the radius and half a pixel,
/// radius 0 moves nothing, and a radius outside [0, 64] is refused.
TEST(StereoFrontEnd, RightRefinementByCorrelationMakesTheDisparityMoreAccurate) {
  const auto orbit = sim::simulate_globe_camera(sim::GlobeCameraOptions{}).true_poses;
  auto detector = make_detector({});
  const RightRefinementOptions refinement{.radius = 5};
  std::vector<double> keypoint_error, refined_error;
  std::size_t moved = 0, matches = 0;
  for (const std::size_t step : {50, 250, 450}) {
    const RenderedPair pair(orbit[step]);
    const cv::Mat left_image = as_mat(pair.images.left), right_image = as_mat(pair.images.right);
    const auto found = match_stereo(detect(left_image, *detector), detect(right_image, *detector));
    auto refined = found;
    auto untouched = found;
    EXPECT_EQ(refine_right_by_correlation(left_image, right_image, untouched, {}), 0u);
    moved += refine_right_by_correlation(left_image, right_image, refined, refinement);
    matches += found.size();
    ASSERT_EQ(refined.size(), found.size());
    for (std::size_t i = 0; i < found.size(); ++i) {
      EXPECT_EQ(untouched[i].right_px, found[i].right_px);
      EXPECT_EQ(refined[i].left_px, found[i].left_px);
      EXPECT_EQ(refined[i].right_px.y(), found[i].right_px.y());
      EXPECT_LE(std::abs(refined[i].right_px.x() - found[i].right_px.x()), refinement.radius + 0.5);
      const auto truth = pair.true_point(found[i].left_px);
      if (!truth) continue;
      const double true_x = pair.rig.focal_px * (truth->x() - pair.rig.baseline) / truth->z() + pair.rig.cx;
      if (std::abs(found[i].right_px.x() - true_x) > 3.0) continue;  // a wrong match: no disparity error to speak of
      keypoint_error.push_back(std::abs(found[i].right_px.x() - true_x));
      refined_error.push_back(std::abs(refined[i].right_px.x() - true_x));
    }
  }
  auto median = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
  };
  auto beyond_a_pixel = [](const std::vector<double>& v) { return std::count_if(v.begin(), v.end(), [](double e) { return e > 1.0; }); };
  std::printf("right x by correlation: %zu of %zu matches moved; median |disparity error| %.3f px against the keypoint's %.3f, "
              "%ld against %ld beyond a pixel\n",
              moved, matches, median(refined_error), median(keypoint_error), beyond_a_pixel(refined_error), beyond_a_pixel(keypoint_error));
  EXPECT_GT(moved, matches / 2);
  EXPECT_LT(median(refined_error), median(keypoint_error));
  EXPECT_LT(beyond_a_pixel(refined_error), beyond_a_pixel(keypoint_error));
  const RenderedPair pair;
  const cv::Mat left_image = as_mat(pair.images.left), colour(left_image.size(), CV_8UC3, cv::Scalar::all(0));
  std::vector<StereoMatch> one = {{0, 0, Eigen::Vector2d(100, 100), Eigen::Vector2d(90, 100), 0.0}};
  EXPECT_THROW(refine_right_by_correlation(left_image, colour, one, refinement), invalid_input_error);
  EXPECT_THROW(search_rows(left_image, colour, Features{}), invalid_input_error);
  EXPECT_EQ(one[0].right_px, Eigen::Vector2d(90, 100));
  for (const int radius : {-1, 65})
    EXPECT_THROW(StereoFrontEnd(pair.rig, {.right_refinement = {.radius = radius}}), invalid_input_error) << radius;
}

/// The disparity measured along the surface's slant (vision/slanted_correlation.hpp) against the
/// ways it is measured without it, on the same descriptor matches along the orbit: the right
/// keypoint's x, the unwarped correlation (right_refinement) and the warp by a plane. Where the globe
/// turns away (slant beyond 45 degrees) the peers measure it short, the stretch of the right image
/// and its curvature across the patch moving their peaks; with the curvature the mean error there is
/// smaller than every peer's, and the RMS error of the warped correlations smaller than the
/// unwarped ones'. No left pixel or row moves, no disparity moves beyond the search and a grid step,
/// and bad options, images or pixels are refused with the matches left as they were.
TEST(StereoFrontEnd, SlantedCorrelationMeasuresTheDisparityOfObliqueSurfacesWithoutBias) {
  const sim::GlobeCameraOptions options;
  const auto orbit = sim::simulate_globe_camera(options).true_poses;
  auto detector = make_detector({});
  const SlantedCorrelationOptions slanted;
  enum Way { keypoint, unwarped, along_plane, along_slant };
  constexpr std::array ways_measured{keypoint, unwarped, along_plane, along_slant};
  std::array<std::vector<double>, 4> oblique, all;  // signed disparity errors beyond 45 degrees; all of them
  for (const std::size_t step : {40, 120, 200, 280, 360, 440}) {
    const RenderedPair pair(orbit[step]);
    const cv::Mat left_image = as_mat(pair.images.left), right_image = as_mat(pair.images.right);
    const Eigen::Vector3d centre = pair.in_camera(Eigen::Vector3d::Zero());
    const auto found = match_stereo(detect(left_image, *detector), detect(right_image, *detector));
    std::array<std::vector<StereoMatch>, 4> ways{found, found, found, found};
    refine_right_by_correlation(left_image, right_image, ways[unwarped], {.radius = 5});
    refine_right_along_slant(left_image, right_image, ways[along_plane], {.curvature = false});
    const auto refined = refine_right_along_slant(left_image, right_image, ways[along_slant], slanted);
    EXPECT_GT(refined.measured, found.size() / 2);
    EXPECT_EQ(refined.dropped, 0u);
    ASSERT_EQ(ways[along_slant].size(), found.size());
    // Dropping the unmeasured leaves the measured ones as they were, in their order.
    auto measured_only = found;
    const auto strict = refine_right_along_slant(left_image, right_image, measured_only, {.drop_unmeasured = true});
    EXPECT_EQ(strict.measured, refined.measured);
    EXPECT_EQ(strict.dropped, found.size() - refined.measured);
    ASSERT_EQ(measured_only.size(), refined.measured);
    for (std::size_t i = 0, k = 0; i < found.size(); ++i)
      if (ways[along_slant][i].right_px != found[i].right_px) {
        EXPECT_EQ(measured_only[k].left_px, found[i].left_px);
        EXPECT_EQ(measured_only[k++].right_px, ways[along_slant][i].right_px);
      }
    for (std::size_t i = 0; i < found.size(); ++i) {
      const StereoMatch& m = ways[along_slant][i];
      EXPECT_EQ(m.left_px, found[i].left_px);
      EXPECT_EQ(m.right_px.y(), found[i].right_px.y());
      EXPECT_LE(std::abs(m.disparity() - found[i].disparity()), slanted.search_px + slanted.step_px);
      const auto truth = pair.true_point(found[i].left_px);
      if (!truth) continue;
      const double true_disparity = pair.rig.focal_px * pair.rig.baseline / truth->z();
      if (std::abs(found[i].disparity() - true_disparity) > 3.0) continue;  // a wrong match
      const bool turned_away = (*truth - centre).normalized().dot(-truth->normalized()) < std::cos(std::acos(-1.0) / 4);
      for (const Way w : ways_measured) {
        const double error = ways[w][i].disparity() - true_disparity;
        all[w].push_back(error);
        if (turned_away) oblique[w].push_back(error);
      }
    }
  }
  auto mean = [](const std::vector<double>& v) { return std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size()); };
  auto rms = [](const std::vector<double>& v) {
    return std::sqrt(std::inner_product(v.begin(), v.end(), v.begin(), 0.0) / static_cast<double>(v.size()));
  };
  std::printf("disparity error beyond a 45 degree slant (%zu matches), mean: keypoint %+.3f, unwarped %+.3f, along a plane "
              "%+.3f, along the slant %+.3f px; RMS of all %zu: %.3f, %.3f, %.3f, %.3f px\n",
              oblique[keypoint].size(), mean(oblique[keypoint]), mean(oblique[unwarped]), mean(oblique[along_plane]),
              mean(oblique[along_slant]), all[keypoint].size(), rms(all[keypoint]), rms(all[unwarped]), rms(all[along_plane]),
              rms(all[along_slant]));
  ASSERT_GE(oblique[keypoint].size(), 200u);
  for (const Way peer : {keypoint, unwarped, along_plane})
    EXPECT_LT(std::abs(mean(oblique[along_slant])), std::abs(mean(oblique[peer]))) << peer;
  for (const Way warped : {along_plane, along_slant})
    for (const Way peer : {keypoint, unwarped}) EXPECT_LT(rms(all[warped]), rms(all[peer])) << warped << " " << peer;
  const RenderedPair pair;
  const cv::Mat left_image = as_mat(pair.images.left), colour(left_image.size(), CV_8UC3, cv::Scalar::all(0));
  std::vector<StereoMatch> one = {{0, 0, Eigen::Vector2d(100, 100), Eigen::Vector2d(90, 100), 0.0}};
  EXPECT_THROW(refine_right_along_slant(left_image, colour, one, slanted), invalid_input_error);
  EXPECT_EQ(one[0].right_px, Eigen::Vector2d(90, 100));
  std::vector<StereoMatch> two = {one[0], {1, 1, Eigen::Vector2d(std::nan(""), 120), Eigen::Vector2d(110, 120), 0.0}};
  EXPECT_THROW(refine_right_along_slant(left_image, left_image, two, slanted), invalid_input_error);
  EXPECT_EQ(two[0].right_px, Eigen::Vector2d(90, 100));
  EXPECT_EQ(two.size(), 2u);
  for (const SlantedCorrelationOptions& bad : {SlantedCorrelationOptions{.search_px = 0.0}, SlantedCorrelationOptions{.step_px = 5.0},
                                              SlantedCorrelationOptions{.half_window = 0},
                                              SlantedCorrelationOptions{.min_correlation = std::nan("")},
                                              SlantedCorrelationOptions{.neighbours = {.min_neighbours = 2}}})
    EXPECT_THROW(StereoFrontEnd(pair.rig, {.slanted_correlation = true, .slanted = bad}), invalid_input_error);
}

/// The floor's bound from the sensor model it protects: at the significant disparity of k standard
/// deviations, PointInCamera3D's first-order depth standard deviation is the depth over k.
TEST(StereoFrontEnd, TheSignificantDisparityIsWhereTheDepthIsKnownToItsStatedShare) {
  const StereoPointNoise noise;  // 0.5 px, f = 600 px, b = 0.1 m: the rendered globe's
  for (const double k : {1.0, 2.0, 3.0}) {
    const double d = significant_disparity(noise.pixel_sigma, k);
    const double z = noise.focal_px * noise.baseline / d;
    const double depth_sigma = std::sqrt(noise.covariance(Eigen::Vector3d(0.0, 0.0, z))(2, 2));
    EXPECT_NEAR(k * depth_sigma / z, 1.0, 1e-12) << k;
  }
  EXPECT_NEAR(significant_disparity(0.5, 2.0), std::sqrt(2.0), 1e-15);
}

/// FrontEndOptions::min_disparity drops exactly the matches below it, counted, and leaves the others
/// (points, descriptors, order) as the front-end without a floor gives them; a floor that is not a
/// finite non-negative number is refused.
TEST(StereoFrontEnd, MatchesBelowTheDisparityFloorAreDroppedAndCounted) {
  const RenderedPair pair;
  StereoFrontEnd all(pair.rig);
  const StereoFrame every = all.process(as_mat(pair.images.left), as_mat(pair.images.right));
  ASSERT_GT(every.features.size(), 10u);
  std::vector<double> disparities;
  for (const auto& f : every.features) disparities.push_back(f.left_px.x() - f.right_px.x());
  std::vector<double> sorted = disparities;
  std::sort(sorted.begin(), sorted.end());
  const double floor = sorted[sorted.size() / 2];  // half the frame's matches below it
  StereoFrontEnd floored(pair.rig, {.min_disparity = floor});
  const StereoFrame kept = floored.process(as_mat(pair.images.left), as_mat(pair.images.right));
  EXPECT_EQ(every.below_min_disparity, 0u);
  EXPECT_GT(kept.below_min_disparity, 0u);
  EXPECT_EQ(kept.features.size() + kept.below_min_disparity, every.features.size());
  ASSERT_EQ(kept.descriptors.rows, static_cast<int>(kept.features.size()));
  std::size_t k = 0;
  for (std::size_t i = 0; i < every.features.size(); ++i) {
    if (disparities[i] < floor) continue;
    ASSERT_LT(k, kept.features.size());
    EXPECT_EQ(kept.features[k].point, every.features[i].point);
    EXPECT_EQ(cv::norm(kept.descriptors.row(static_cast<int>(k)), every.descriptors.row(static_cast<int>(i)), cv::NORM_L1), 0.0);
    ++k;
  }
  EXPECT_EQ(k, kept.features.size());
  for (const double bad : {-1.0, std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()})
    EXPECT_THROW(StereoFrontEnd(pair.rig, {.min_disparity = bad}), invalid_input_error) << bad;
}

/// Points on a plane whose normal is `slant` from the optical axis, seen through a grid of pixels
/// 10 px apart around the image centre (f 600 px): each one's scale is 1 / cos of the angle between
/// its own ray and the plane's normal, at most max_scale; a point with no neighbours keeps 1.
TEST(StereoFrontEnd, TheSlantNoiseScaleIsOneOverTheCosineOfTheSurfacesSlant) {
  for (const auto& [slant_deg, max_scale] : {std::pair{0.0, 10.0}, {30.0, 10.0}, {60.0, 10.0}, {75.0, 10.0}, {75.0, 2.5}}) {
    const double slant = slant_deg * std::acos(-1.0) / 180.0;
    const Eigen::Vector3d normal(std::sin(slant), 0.0, -std::cos(slant));
    std::vector<Eigen::Vector2d> pixels;
    std::vector<Eigen::Vector3d> points;
    for (int i = -5; i <= 5; ++i)
      for (int j = -5; j <= 5; ++j) {
        const Eigen::Vector3d ray(10.0 * i / 600.0, 10.0 * j / 600.0, 1.0);
        pixels.emplace_back(320.0 + 10.0 * i, 240.0 + 10.0 * j);
        points.push_back(ray * (-1.0 / normal.dot(ray)));  // on the plane n . p = -1, in front of the camera
      }
    pixels.emplace_back(20.0, 20.0);  // alone: more than 40 px from every other point
    points.emplace_back(-0.5, -0.4, 1.0);
    const auto scales = slant_noise_scales(pixels, points, {.max_scale = max_scale});
    ASSERT_EQ(scales.size(), points.size());
    for (std::size_t k = 0; k + 1 < points.size(); ++k) {
      const double expected = std::min(max_scale, 1.0 / std::abs(normal.dot(points[k].normalized())));
      EXPECT_NEAR(scales[k], expected, 1e-6 * expected) << slant_deg << " degrees, point " << k;
    }
    EXPECT_EQ(scales.back(), 1.0);
  }
  const std::vector<Eigen::Vector2d> two(2, Eigen::Vector2d::Zero());
  const std::vector<Eigen::Vector3d> three(3, Eigen::Vector3d::UnitZ());
  EXPECT_THROW((void)slant_noise_scales(two, three), invalid_input_error);
  for (const SlantNoiseOptions bad : {SlantNoiseOptions{.radius_px = 0.0}, SlantNoiseOptions{.min_neighbours = 2},
                                      SlantNoiseOptions{.max_scale = 0.5},
                                      SlantNoiseOptions{.max_scale = std::numeric_limits<double>::infinity()}}) {
    EXPECT_THROW((void)slant_noise_scales(two, std::vector<Eigen::Vector3d>(2, Eigen::Vector3d::UnitZ()), bad),
                 invalid_input_error);
    EXPECT_THROW(StereoFrontEnd(StereoRig{}, {.slant_noise = true, .slant = bad}), invalid_input_error);
  }
}

/// On a rendered pair the front-end's slant (from its scale, where neither 1 nor capped) follows the
/// globe's: the plane is fitted to points within 40 px, about 2 cm of surface at the orbit's 0.3 m,
/// over which the sphere's (radius 0.15 m) normal turns by up to +-4 degrees, and the points' depth
/// noise tilts it further; so the median error is held to 10 degrees.
TEST(StereoFrontEnd, TheFrontEndsSlantFollowsTheGlobesSurface) {
  const RenderedPair pair;
  StereoFrontEnd front_end(pair.rig, {.slant_noise = true});
  const auto frame = front_end.process(as_mat(pair.images.left), as_mat(pair.images.right));
  const Eigen::Vector3d centre = pair.in_camera(Eigen::Vector3d::Zero());  // the globe's centre, camera frame
  std::vector<double> errors;
  std::size_t oblique = 0;
  for (const auto& f : frame.features) {
    const auto truth = pair.true_point(f.left_px);
    if (!truth || !(f.noise_scale > 1.0) || !(f.noise_scale < 10.0)) continue;
    const double true_slant = std::acos(std::abs((*truth - centre).normalized().dot(truth->normalized())));
    errors.push_back(std::abs(std::acos(1.0 / f.noise_scale) - true_slant));
    oblique += true_slant > std::acos(0.5);
  }
  ASSERT_GE(errors.size(), 100u);
  std::sort(errors.begin(), errors.end());
  const double median_deg = errors[errors.size() / 2] * 180.0 / std::acos(-1.0);
  std::printf("%zu features with a slant (%zu beyond 60 degrees): median error %.2f degrees\n", errors.size(), oblique,
              median_deg);
  EXPECT_LT(median_deg, 10.0);
  EXPECT_GT(oblique, 0u);
}

/// A plane's matches on a grid 10 px apart (disparity 100 + 0.2 u px), a patch of a nearer surface
/// in one corner (disparity 180, a depth edge), a match alone: all kept. Wrong matches planted inside
/// the grid are dropped: disparity 1.7 px (as the one that lost the camera on seed 7), 400 px, 8 px
/// too much (8 of the disparity's noise floor of 1 px, twice the interval's 4), two side by side that
/// agree with each other (the robust step leaves each out of the other's plane), and one 60 px right
/// of the grid, alone within 40 px (judged on the doubled radius). Options out of range, lists of
/// different lengths, a NaN disparity: refused.
TEST(StereoFrontEnd, AMatchWhoseDisparityItsNeighboursDoNotBearOutIsDropped) {
  std::vector<Eigen::Vector2d> pixels;
  std::vector<double> disparities;
  for (int i = 0; i < 20; ++i)
    for (int j = 0; j < 15; ++j) {
      pixels.emplace_back(100.0 + 10.0 * i, 100.0 + 10.0 * j);
      disparities.push_back(i < 4 && j < 4 ? 180.0 : 100.0 + 0.2 * pixels.back().x());
    }
  pixels.emplace_back(600.0, 450.0);  // alone
  disparities.push_back(3.0);
  const std::size_t honest = pixels.size();
  for (const auto& [u, v, d] : {std::tuple{155.0, 155.0, 1.7}, {205.0, 175.0, 400.0}, {225.0, 185.0, 100.0 + 0.2 * 225.0 + 8.0},
                                {245.0, 205.0, 9.0}, {246.0, 206.0, 9.5}, {350.0, 170.0, 20.0}}) {
    pixels.emplace_back(u, v);
    disparities.push_back(d);
  }
  const auto kept = disparity_supported(pixels, disparities);
  ASSERT_EQ(kept.size(), pixels.size());
  for (std::size_t i = 0; i < honest; ++i) EXPECT_TRUE(kept[i]) << "honest match " << i;
  for (std::size_t i = honest; i < pixels.size(); ++i) EXPECT_FALSE(kept[i]) << "wrong match " << i;

  const std::vector<double> two{1.0, 2.0};
  EXPECT_THROW((void)disparity_supported(std::vector<Eigen::Vector2d>(3), two), invalid_input_error);
  EXPECT_THROW((void)disparity_supported(std::vector<Eigen::Vector2d>(2), std::vector<double>{1.0, std::nan("")}),
               invalid_input_error);
  for (const DisparitySupportOptions bad :
       {DisparitySupportOptions{.radius_px = 0.0}, DisparitySupportOptions{.min_neighbours = 3},
        DisparitySupportOptions{.sigmas = -1.0}, DisparitySupportOptions{.min_sigma_px = 0.0},
        DisparitySupportOptions{.sigmas = std::numeric_limits<double>::infinity()},
        DisparitySupportOptions{.max_radius_px = 39.0}}) {
    EXPECT_THROW((void)disparity_supported(std::vector<Eigen::Vector2d>(2), two, bad), invalid_input_error);
    EXPECT_THROW(StereoFrontEnd(StereoRig{}, {.disparity_support = true, .support = bad}), invalid_input_error);
  }
}

/// Along the orbit, the support test against the rendering. It drops at most 1% of the right matches
/// (the globe is one smooth surface whose disparity gradient is far below the limit of 1 except at
/// its rim). Every 10th match made wrong by hand, its disparity replaced by one between the 1.41 px
/// floor and half its own (a depth at least twice the true one, as the match that lost the camera
/// on seed 7), one at a time: each that the test judges is dropped, since the plane of its right
/// neighbours predicts a disparity more than 65 px away (half of 130-190 px) with a scatter of a few
/// pixels. The front-end with the option drops exactly the matches the function flags, and counts
/// them. The wrong matches the detector makes itself are counted too.
TEST(StereoFrontEnd, TheDisparitySupportTestDropsMatchesFarOffTheGlobeAndKeepsTheRightOnes) {
  const sim::GlobeCameraOptions options;
  const auto orbit = sim::simulate_globe_camera(options).true_poses;
  const DisparitySupportOptions o;
  std::size_t right = 0, right_dropped = 0, planted = 0, planted_judged = 0, planted_dropped = 0, wrong = 0,
              wrong_dropped = 0;
  for (const std::size_t step : {0, 100, 200, 300, 400}) {
    const RenderedPair pair(orbit[step]);
    StereoFrontEnd all(pair.rig), supported(pair.rig, {.disparity_support = true});
    const StereoFrame every = all.process(as_mat(pair.images.left), as_mat(pair.images.right));
    const StereoFrame kept = supported.process(as_mat(pair.images.left), as_mat(pair.images.right));
    std::vector<Eigen::Vector2d> pixels;
    std::vector<double> disparities;
    for (const auto& f : every.features) pixels.push_back(f.left_px), disparities.push_back(f.left_px.x() - f.right_px.x());
    const auto flags = disparity_supported(pixels, disparities, o);
    const auto dropped = static_cast<std::size_t>(std::count(flags.begin(), flags.end(), false));
    EXPECT_EQ(kept.without_support, dropped);
    EXPECT_EQ(kept.features.size() + dropped, every.features.size());
    std::vector<bool> is_right(pixels.size());
    for (std::size_t i = 0; i < pixels.size(); ++i) {
      const auto& f = every.features[i];
      is_right[i] = pair.true_point(f.left_px) && pair.is_right({0, 0, f.left_px, f.right_px}, f.size);
      right += is_right[i];
      right_dropped += is_right[i] && !flags[i];
      wrong += !is_right[i];
      wrong_dropped += !is_right[i] && !flags[i];
    }
    std::vector<int> near;
    const detail::PixelNeighbours neighbours(pixels);
    for (std::size_t i = 0; i < pixels.size(); i += 10) {  // one at a time among the frame's own matches
      if (!is_right[i]) continue;
      ++planted;
      (void)detail::neighbourhood(neighbours, i, o, near);
      if (static_cast<int>(near.size()) < o.min_neighbours) continue;
      ++planted_judged;
      std::vector<double> corrupted = disparities;
      const double share = static_cast<double>((i * 7919) % 1000) / 1000.0;  // spread over [0, 1)
      corrupted[i] = std::sqrt(2.0) + share * (0.5 * disparities[i] - std::sqrt(2.0));
      planted_dropped += !disparity_supported(pixels, corrupted, o)[i];
    }
  }
  std::printf("%zu right matches over 5 frames, %zu of them dropped; %zu wrong by the detector, %zu dropped; %zu "
              "made wrong by hand (%zu with enough neighbours to judge), %zu dropped\n",
              right, right_dropped, wrong, wrong_dropped, planted, planted_judged, planted_dropped);
  EXPECT_LE(static_cast<double>(right_dropped), 0.01 * static_cast<double>(right));
  EXPECT_GE(planted_judged, 250u);
  EXPECT_EQ(planted_dropped, planted_judged);
}

TEST(StereoFrontEnd, AFlatImageHasNoFeaturesAndAnEmptyOneIsAnError) {
  auto detector = make_detector({});
  const cv::Mat flat(480, 640, CV_8UC1, cv::Scalar(90));
  const auto none = detect(flat, *detector);
  EXPECT_TRUE(none.keypoints.empty());
  EXPECT_TRUE(match_stereo(none, none).empty());
  EXPECT_THROW((void)detect(cv::Mat(), *detector), invalid_input_error);
  EXPECT_THROW((void)detect(cv::Mat(480, 640, CV_32FC1, cv::Scalar(0.0f)), *detector), invalid_input_error);
  StereoMatch backwards{0, 0, {100.0, 50.0}, {120.0, 50.0}, 0.0};
  EXPECT_THROW((void)triangulate(StereoRig{}, backwards), invalid_input_error);
  for (const DetectorOptions bad : {DetectorOptions{.threshold = 0.0f}, DetectorOptions{.threshold = NAN},
                                    DetectorOptions{.octave_layers = 0}, DetectorOptions{.orb_features = 0},
                                    DetectorOptions{.detector = Detector::orb, .orb_levels = 0}})
    EXPECT_THROW((void)make_detector(bad), invalid_input_error);
}

}  // namespace
}  // namespace sextant::vision
