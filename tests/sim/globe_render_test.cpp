// The rendered stereo globe (sim/globe_render.hpp): deterministic images, pixel rays that meet the
// sphere where the camera model says, and a texture that looks the same from both cameras, which is
// what lets a front-end match features left to right.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "sextant/sim/globe_render.hpp"

namespace sextant::sim {
namespace {

struct Scene {
  GlobeCameraOptions options;
  Vector12d pose;
  Scene() : pose(detail::orbit_start(options)) {}

  /// Left and right pixel of a world point, image coordinates (principal point at the centre).
  std::pair<Eigen::Vector2d, Eigen::Vector2d> project(const Eigen::Vector3d& m) const {
    const Eigen::Matrix3d R = euler_yxz::rotation(pose.segment<3>(3));
    const Eigen::Vector3d q = R.transpose() * (m - pose.head<3>());
    const double f = options.stereo.focal_px, cx = 0.5 * options.image_width, cy = 0.5 * options.image_height;
    const Eigen::Vector2d left(cx + f * q.x() / q.z(), cy + f * q.y() / q.z());
    return {left, left - Eigen::Vector2d(f * options.stereo.baseline / q.z(), 0.0)};
  }
};

TEST(GlobeRender, IsDeterministicForASeedAndChangesWithIt) {
  Scene s;
  const auto a = render_stereo(s.options, s.pose);
  const auto b = render_stereo(s.options, s.pose);
  EXPECT_EQ(a.left.pixels, b.left.pixels);
  EXPECT_EQ(a.right.pixels, b.right.pixels);
  EXPECT_NE(a.left.pixels, a.right.pixels);
  const auto other = render_stereo(s.options, s.pose, {.texture_seed = 2});
  EXPECT_NE(a.left.pixels, other.left.pixels);
  const auto noisy = render_stereo(s.options, s.pose, {.pixel_noise = 3.0});
  EXPECT_NE(a.left.pixels, noisy.left.pixels);
  EXPECT_EQ(noisy.left.pixels, render_stereo(s.options, s.pose, {.pixel_noise = 3.0}).left.pixels);
}

TEST(GlobeRender, APixelsSurfacePointLiesOnTheGlobeAndProjectsBackToIt) {
  Scene s;
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(0.0, s.options.image_width - 1.0), v(0.0, s.options.image_height - 1.0);
  int hits = 0;
  for (int i = 0; i < 2000; ++i) {
    const double pu = u(rng), pv = v(rng);
    const auto m = surface_point(s.options, s.pose, pu, pv);
    if (!m) continue;
    ++hits;
    EXPECT_NEAR(m->norm(), s.options.globe_radius, 1e-12);
    const auto [left, right] = s.project(*m);
    EXPECT_NEAR(left.x(), pu, 1e-8);
    EXPECT_NEAR(left.y(), pv, 1e-8);
    EXPECT_LT(right.x(), left.x());  // positive disparity
  }
  // At the orbit's start the globe fills part of the frame: the optical axis points at its centre.
  EXPECT_GT(hits, 100);
  EXPECT_LT(hits, 2000);
  ASSERT_TRUE(surface_point(s.options, s.pose, 0.5 * s.options.image_width, 0.5 * s.options.image_height));
}

TEST(GlobeRender, BackgroundIsFlatAndTheGlobeIsTextured) {
  Scene s;
  const GlobeRenderOptions r;
  const auto images = render_stereo(s.options, s.pose, r);
  double sum = 0.0, squares = 0.0;
  int n = 0;
  for (int v = 0; v < s.options.image_height; v += 2)
    for (int u = 0; u < s.options.image_width; u += 2) {
      // a pixel whose whole footprint misses the globe is exactly the background
      bool all_miss = true;
      for (const double du : {-0.5, 0.5})
        for (const double dv : {-0.5, 0.5}) all_miss = all_miss && !surface_point(s.options, s.pose, u + du, v + dv);
      if (all_miss) {
        ASSERT_EQ(images.left.at(u, v), r.background) << u << ", " << v;
        continue;
      }
      if (!surface_point(s.options, s.pose, u, v)) continue;
      const double g = images.left.at(u, v);
      sum += g;
      squares += g * g;
      ++n;
    }
  ASSERT_GT(n, 1000);
  const double mean = sum / n, sd = std::sqrt(squares / n - mean * mean);
  // Light and dark patches: the texture spans the grey range (tanh pushes the noise to +-110 grey
  // levels around 127.5); a flat or washed-out texture would give a feature detector nothing.
  EXPECT_GT(sd, 40.0);
  EXPECT_NEAR(mean, 127.5, 40.0);
}

TEST(GlobeRender, ASurfacePointLooksTheSameFromBothCameras) {
  Scene s;
  const auto images = render_stereo(s.options, s.pose);
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0.0, s.options.image_width - 1.0), v(0.0, s.options.image_height - 1.0);
  double same = 0.0, shifted = 0.0;
  int n = 0;
  for (int i = 0; i < 20000 && n < 500; ++i) {
    const int pu = static_cast<int>(std::lround(u(rng))), pv = static_cast<int>(std::lround(v(rng)));
    const auto m = surface_point(s.options, s.pose, pu, pv);
    if (!m) continue;
    const auto [left, right] = s.project(*m);
    const int ru = static_cast<int>(std::lround(right.x()));
    if (ru < 8 || ru >= s.options.image_width - 8) continue;
    // inside the globe's disc in the right image too (not at its limb)
    if (!surface_point(s.options, s.pose, pu + 4, pv) || !surface_point(s.options, s.pose, pu - 4, pv)) continue;
    same += std::abs(double(images.left.at(pu, pv)) - images.right.at(ru, pv));
    shifted += std::abs(double(images.left.at(pu, pv)) - images.right.at(ru + 7, pv));
    ++n;
  }
  ASSERT_EQ(n, 500);
  // The corresponding pixel differs by rounding of the projection (under half a pixel, a few grey
  // levels on the texture's slopes); a pixel 7 columns off is another patch of texture.
  EXPECT_LT(same / n, 0.25 * shifted / n) << "mean |difference|: corresponding " << same / n << ", shifted " << shifted / n;
}

}  // namespace
}  // namespace sextant::sim
