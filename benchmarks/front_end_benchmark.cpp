// The stereo front-end's cost per rendered pair with each detector camera_rate.ini has run (issue 37):
// AKAZE with 2 sublevels per octave against ORB with every corner at full resolution, on the same ten
// pairs of the globe's orbit, in one run (docs/results/real_time.md, "ORB"). BM_DetectOneImage: the
// detector alone on one core; BM_StereoFrontEnd: a whole pair as the pipeline's front-end thread runs it
// (both images on two threads, matching, disparities along the slant, triangulation).
#include <benchmark/benchmark.h>

#include <opencv2/core.hpp>
#include <vector>

#include "sextant/sim/globe_render.hpp"
#include "sextant/vision/features.hpp"
#include "sextant/vision/globe_calibration.hpp"
#include "sextant/vision/gray_image_view.hpp"
#include "sextant/vision/opencv_threads.hpp"
#include "sextant/vision/stereo_front_end.hpp"

namespace {

using namespace sextant;

/// Frames 0, 50, ..., 450 of the default orbit, rendered once.
const std::vector<sim::StereoImages>& rendered_pairs() {
  static const std::vector<sim::StereoImages> pairs = [] {
    const sim::GlobeCameraOptions options;
    const auto orbit = sim::simulate_globe_camera(options).true_poses;
    std::vector<sim::StereoImages> out;
    for (std::size_t k = 0; k < 500 && k < orbit.size(); k += 50) out.push_back(sim::render_stereo(options, orbit[k]));
    return out;
  }();
  return pairs;
}

/// Argument 0: AKAZE, 2 sublevels per octave; 1: ORB, one pyramid level.
vision::DetectorOptions detector_of(const benchmark::State& state) {
  if (state.range(0) == 0) return {.detector = vision::Detector::akaze, .octave_layers = 2};
  return {.detector = vision::Detector::orb, .orb_levels = 1};
}

/// One image (or pair) an iteration, taking the ten in turn: the time column is per image (pair).
void BM_DetectOneImage(benchmark::State& state) {
  const vision::OpenCvThreads one_thread(1);
  const auto& pairs = rendered_pairs();
  auto detector = vision::make_detector(detector_of(state));
  std::size_t keypoints = 0, k = 0;
  for (auto _ : state) keypoints += vision::detect(vision::as_mat(pairs[k++ % pairs.size()].left), *detector).keypoints.size();
  state.counters["keypoints_per_image"] = static_cast<double>(keypoints) / static_cast<double>(k);
}

void BM_StereoFrontEnd(benchmark::State& state) {
  const vision::OpenCvThreads one_thread(1);
  const auto& pairs = rendered_pairs();
  const sim::GlobeCameraOptions o;
  const vision::StereoRig rig = vision::globe_rig(o);
  vision::FrontEndOptions options{.detector = detector_of(state), .slanted_correlation = true};
  options.slanted.drop_unmeasured = true;
  vision::StereoFrontEnd front_end(rig, options);
  std::size_t features = 0, k = 0;
  for (auto _ : state) {
    const auto& pair = pairs[k++ % pairs.size()];
    features += front_end.process(vision::as_mat(pair.left), vision::as_mat(pair.right)).features.size();
  }
  state.counters["stereo_features_per_pair"] = static_cast<double>(features) / static_cast<double>(k);
}

}  // namespace

BENCHMARK(BM_DetectOneImage)->Arg(0)->Arg(1)->ArgName("orb")->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(2.0);
BENCHMARK(BM_StereoFrontEnd)->Arg(0)->Arg(1)->ArgName("orb")->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(2.0);

BENCHMARK_MAIN();
