#pragma once
/// \file The globe of sim/globe_camera.hpp rendered as a rectified stereo pair of grayscale images,
/// for the visual front-end (issue 12). Per pixel, rays from the camera centre meet the sphere
/// |o + t d| = r at the nearest t > 0 and take the brightness of a procedural texture fixed to the
/// globe's surface, so every view of a surface point shows the same pattern (no shading, no
/// third-party images). Deterministic for a texture seed, with optional Gaussian pixel noise. The
/// true surface point behind any pixel is known (surface_point), hence every feature's true 3D point.

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>
#include <random>
#include <vector>

#include "sextant/core/gray_image.hpp"
#include "sextant/models/euler_camera_12d.hpp"
#include "sextant/sim/globe_camera.hpp"

namespace sextant::sim {

using sextant::GrayImage;  // core/gray_image.hpp

struct StereoImages {
  GrayImage left, right;
};

struct GlobeRenderOptions {
  std::uint64_t texture_seed = 1;
  int supersampling = 2;            ///< rays per pixel side (anti-aliasing)
  double pixel_noise = 0.0;         ///< grey levels, Gaussian, per pixel; 0 = noise-free
  std::uint64_t noise_seed = 1;
  std::uint8_t background = 40;     ///< grey level where no ray meets the globe
  /// Base frequency of the texture on the unit sphere; each octave doubles it. 10 puts the coarsest
  /// blobs at ~1.5 cm on the thesis's 15 cm globe (~20 px at the orbit's distance and 600 px focal
  /// length); five octaves reach below a pixel, which the supersampling averages out. Measured with
  /// AKAZE at the orbit's start: ~1700 features per image, 99.5% of stereo matches right
  /// (tests/vision/stereo_front_end_test.cpp); 5 and four octaves gave a third of the features.
  double base_frequency = 10.0;
  int octaves = 5;
};

/// Brightness in [0, 255] of the globe's surface at a unit direction: value noise over a 3D
/// lattice (hashed, smoothstep-interpolated), summed over octaves, pushed apart by tanh into
/// light and dark patches with soft edges.
class GlobeTexture {
 public:
  explicit GlobeTexture(const GlobeRenderOptions& o) : seed_(o.texture_seed), frequency_(o.base_frequency), octaves_(o.octaves) {}

  double brightness(const Eigen::Vector3d& unit) const {
    double sum = 0.0, amplitude = 1.0, frequency = frequency_;
    for (int k = 0; k < octaves_; ++k, amplitude *= 0.5, frequency *= 2.0)
      sum += amplitude * value_noise(frequency * unit, static_cast<std::uint64_t>(k));
    return 127.5 + 110.0 * std::tanh(2.5 * sum);
  }

 private:
  static std::uint64_t mix(std::uint64_t z) {  // splitmix64's finalizer
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  }
  /// A value in [-1, 1] per lattice node, octave and seed.
  double lattice(std::int64_t x, std::int64_t y, std::int64_t z, std::uint64_t octave) const {
    std::uint64_t h = mix(seed_ + 0x9e3779b97f4a7c15ULL * (octave + 1));
    h = mix(h ^ static_cast<std::uint64_t>(x));
    h = mix(h ^ static_cast<std::uint64_t>(y));
    h = mix(h ^ static_cast<std::uint64_t>(z));
    return static_cast<double>(h >> 11) * (2.0 / 9007199254740992.0) - 1.0;
  }
  double value_noise(const Eigen::Vector3d& p, std::uint64_t octave) const {
    const Eigen::Vector3d floor = p.array().floor();
    const Eigen::Vector3d f = p - floor;
    const Eigen::Vector3d s = f.array().square() * (3.0 - 2.0 * f.array());  // smoothstep
    const auto x = static_cast<std::int64_t>(floor.x()), y = static_cast<std::int64_t>(floor.y()),
               z = static_cast<std::int64_t>(floor.z());
    double corners[2][2][2];
    for (int i = 0; i < 2; ++i)
      for (int j = 0; j < 2; ++j)
        for (int k = 0; k < 2; ++k) corners[i][j][k] = lattice(x + i, y + j, z + k, octave);
    auto lerp = [](double a, double b, double t) { return a + t * (b - a); };
    double plane[2];
    for (int k = 0; k < 2; ++k)
      plane[k] = lerp(lerp(corners[0][0][k], corners[1][0][k], s.x()), lerp(corners[0][1][k], corners[1][1][k], s.x()), s.y());
    return lerp(plane[0], plane[1], s.z());
  }

  std::uint64_t seed_;
  double frequency_;
  int octaves_;
};

namespace detail {

/// The nearest t > 0 with |origin + t direction| = radius (direction of unit length), if any.
inline std::optional<double> ray_meets_sphere(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction, double radius) {
  const double b = origin.dot(direction), c = origin.squaredNorm() - radius * radius;
  const double discriminant = b * b - c;
  if (discriminant < 0.0) return std::nullopt;
  const double root = std::sqrt(discriminant);
  const double near = -b - root, far = -b + root;
  if (near > 0.0) return near;
  if (far > 0.0) return far;  // the camera inside the globe: never on the orbit
  return std::nullopt;
}

/// The world direction of pixel (u, v) of a camera with rotation R (camera to world).
inline Eigen::Vector3d pixel_ray(const GlobeCameraOptions& o, const Eigen::Matrix3d& R, double u, double v) {
  const double cx = 0.5 * o.image_width, cy = 0.5 * o.image_height;
  return (R * Eigen::Vector3d((u - cx) / o.stereo.focal_px, (v - cy) / o.stereo.focal_px, 1.0)).normalized();
}

inline GrayImage render_view(const GlobeCameraOptions& o, const GlobeRenderOptions& r, const GlobeTexture& texture,
                             const Eigen::Matrix3d& R, const Eigen::Vector3d& centre, std::mt19937_64& noise) {
  GrayImage image{o.image_width, o.image_height, {}};
  image.pixels.resize(static_cast<std::size_t>(o.image_width) * o.image_height);
  const int n = std::max(1, r.supersampling);
  std::normal_distribution<double> grey(0.0, r.pixel_noise);
  for (int v = 0; v < o.image_height; ++v)
    for (int u = 0; u < o.image_width; ++u) {
      double sum = 0.0;
      for (int a = 0; a < n; ++a)
        for (int b = 0; b < n; ++b) {
          // pixel (u, v) covers [u - 0.5, u + 0.5): its centre is at integer coordinates
          const Eigen::Vector3d d = pixel_ray(o, R, u - 0.5 + (a + 0.5) / n, v - 0.5 + (b + 0.5) / n);
          const auto t = ray_meets_sphere(centre, d, o.globe_radius);
          sum += t ? texture.brightness((centre + *t * d).normalized()) : static_cast<double>(r.background);
        }
      double value = sum / (n * n);
      if (r.pixel_noise > 0.0) value += grey(noise);
      image.pixels[static_cast<std::size_t>(v) * o.image_width + u] =
          static_cast<std::uint8_t>(std::clamp(std::lround(value), 0L, 255L));
    }
  return image;
}

}  // namespace detail

/// The left camera's centre is the pose's position; the right one sits `baseline` along the
/// camera's +x (the model's u_right = u_left - f b / z).
inline StereoImages render_stereo(const GlobeCameraOptions& o, const Vector12d& x, const GlobeRenderOptions& r = {},
                                  std::uint64_t frame = 0) {
  const GlobeTexture texture(r);
  const Eigen::Matrix3d R = euler_yxz::rotation(x.segment<3>(3));
  const Eigen::Vector3d left = x.head<3>(), right = left + o.stereo.baseline * R.col(0);
  std::mt19937_64 noise(r.noise_seed * 0x9e3779b97f4a7c15ULL + frame);
  StereoImages out;
  out.left = detail::render_view(o, r, texture, R, left, noise);
  out.right = detail::render_view(o, r, texture, R, right, noise);
  return out;
}

enum class StereoSide { left, right };

/// The world point of the globe's surface seen at pixel (u, v) of the left (or right) camera at
/// pose x, or nothing when that ray misses the globe.
inline std::optional<Eigen::Vector3d> surface_point(const GlobeCameraOptions& o, const Vector12d& x, double u, double v,
                                                    StereoSide side = StereoSide::left) {
  const Eigen::Matrix3d R = euler_yxz::rotation(x.segment<3>(3));
  const Eigen::Vector3d centre = side == StereoSide::left ? Eigen::Vector3d(x.head<3>())
                                                          : Eigen::Vector3d(x.head<3>() + o.stereo.baseline * R.col(0));
  const Eigen::Vector3d d = detail::pixel_ray(o, R, u, v);
  const auto t = detail::ray_meets_sphere(centre, d, o.globe_radius);
  if (!t) return std::nullopt;
  return Eigen::Vector3d(centre + *t * d);
}

/// A world point in the left camera's frame at pose x (x right, y down, z forward).
inline Eigen::Vector3d in_left_camera(const Vector12d& x, const Eigen::Vector3d& world) {
  return euler_yxz::rotation(x.segment<3>(3)).transpose() * (world - x.head<3>());
}

/// The left image's pixel of a point q in the left camera's frame (z > 0).
inline Eigen::Vector2d left_pixel(const GlobeCameraOptions& o, const Eigen::Vector3d& q) {
  return {0.5 * o.image_width + o.stereo.focal_px * q.x() / q.z(), 0.5 * o.image_height + o.stereo.focal_px * q.y() / q.z()};
}

/// How far from a keypoint [px] a point still falls on the patch it describes: its radius (half its
/// size), at least 2 px.
inline double keypoint_support_px(double size) { return std::max(0.5 * size, 2.0); }

/// The rendering's answer key for a stereo match seen from pose x: right when the surface behind its
/// right keypoint, seen from the left camera, falls inside the left keypoint's support
/// (keypoint_support_px), so both keypoints describe the same patch of the globe.
inline bool stereo_match_is_right(const GlobeCameraOptions& o, const Vector12d& x, const Eigen::Vector2d& left_px,
                                  const Eigen::Vector2d& right_px, double left_size) {
  const auto seen_right = surface_point(o, x, right_px.x(), right_px.y(), StereoSide::right);
  return seen_right && (left_pixel(o, in_left_camera(x, *seen_right)) - left_px).norm() <= keypoint_support_px(left_size);
}

}  // namespace sextant::sim
