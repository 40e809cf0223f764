#pragma once
/// \file A run as an MRPT 3D scene (`.3Dscene`, opens in SceneViewer3D from Debian's mrpt-apps):
/// estimated and ground-truth trajectories, the estimated landmarks with covariance ellipses
/// (planar) or ellipsoids (3D) at a chosen quantile, the true landmarks, and FastSLAM's particles.
/// Every top-level object is named, so a viewer or a test can find it with getByName().

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <map>
#include <mrpt/opengl/CEllipsoid2D.h>
#include <mrpt/opengl/CEllipsoid3D.h>
#include <mrpt/opengl/COpenGLScene.h>
#include <mrpt/opengl/CGridPlaneXY.h>
#include <mrpt/opengl/CPointCloud.h>
#include <mrpt/opengl/CSetOfLines.h>
#include <mrpt/opengl/CSetOfObjects.h>
#include <string>
#include <vector>

#include "sextant/core/error.hpp"
#include "sextant/core/gaussian.hpp"
#include "sextant/core/observation.hpp"

namespace sextant::mrpt_io {

/// What a scene shows; positions in metres (2D positions get z = 0).
struct SceneContent {
  struct Landmark {
    LandmarkId id = 0;
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
    bool planar = true;  ///< draw the 2x2 block as an ellipse
  };
  std::vector<Eigen::Vector3d> estimated_path, true_path;
  std::vector<Landmark> landmarks;
  std::vector<Eigen::Vector3d> true_landmarks;
  std::vector<Eigen::Vector3d> particles;
};

/// Object names in the scene.
namespace scene_names {
inline constexpr const char* estimated_path = "estimated trajectory";
inline constexpr const char* true_path = "ground-truth trajectory";
inline constexpr const char* landmarks = "landmarks";
inline constexpr const char* true_landmarks = "ground-truth landmarks";
inline constexpr const char* particles = "particles";
}  // namespace scene_names

struct SceneOptions {
  double quantile = 3.0;  ///< ellipse/ellipsoid size in standard deviations
};

namespace detail {

inline ::mrpt::opengl::CSetOfLines::Ptr path_lines(const std::vector<Eigen::Vector3d>& path, const char* name,
                                                   float r, float g, float b) {
  auto lines = ::mrpt::opengl::CSetOfLines::Create();
  lines->setName(name);
  lines->setColor(r, g, b);
  lines->setLineWidth(2.0f);
  for (std::size_t k = 1; k < path.size(); ++k)
    lines->appendLine(path[k - 1].x(), path[k - 1].y(), path[k - 1].z(), path[k].x(), path[k].y(), path[k].z());
  return lines;
}

inline ::mrpt::opengl::CPointCloud::Ptr point_cloud(const std::vector<Eigen::Vector3d>& points, const char* name,
                                                    float r, float g, float b, float size) {
  auto cloud = ::mrpt::opengl::CPointCloud::Create();
  cloud->setName(name);
  cloud->setColor(r, g, b);
  cloud->setPointSize(size);
  for (const auto& p : points) cloud->insertPoint(static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z()));
  return cloud;
}

inline ::mrpt::opengl::CRenderizable::Ptr landmark_ellipse(const SceneContent::Landmark& landmark, double quantile) {
  if (landmark.planar) {
    auto ellipse = ::mrpt::opengl::CEllipsoid2D::Create();
    ellipse->setCovMatrix(::mrpt::math::CMatrixDouble22(Eigen::Matrix2d(landmark.cov.topLeftCorner<2, 2>())));
    ellipse->setLocation(landmark.mean.x(), landmark.mean.y(), 0.0);
    ellipse->setQuantiles(static_cast<float>(quantile));
    ellipse->setColor(0.0f, 0.0f, 1.0f);
    ellipse->setName("landmark " + std::to_string(landmark.id));
    return ellipse;
  }
  auto ellipsoid = ::mrpt::opengl::CEllipsoid3D::Create();
  ellipsoid->setCovMatrix(::mrpt::math::CMatrixDouble33(landmark.cov));
  ellipsoid->setLocation(landmark.mean.x(), landmark.mean.y(), landmark.mean.z());
  ellipsoid->setQuantiles(static_cast<float>(quantile));
  ellipsoid->setColor(0.0f, 0.0f, 1.0f, 0.5f);
  ellipsoid->setName("landmark " + std::to_string(landmark.id));
  return ellipsoid;
}

}  // namespace detail

/// The scene: a grid, the trajectories (estimate red, truth black), the landmark ellipses (blue)
/// in a set named "landmarks", the true landmarks (green points), the particles (orange points).
inline ::mrpt::opengl::COpenGLScene::Ptr make_scene(const SceneContent& content, const SceneOptions& options = {}) {
  if (!(options.quantile > 0.0)) throw invalid_input_error("scene quantile must be positive");
  auto scene = ::mrpt::opengl::COpenGLScene::Create();
  Eigen::AlignedBox3d box;
  for (const auto& p : content.estimated_path) box.extend(p);
  for (const auto& l : content.landmarks) box.extend(l.mean);
  if (!box.isEmpty()) {
    const double margin = 0.1 * box.diagonal().norm() + 1.0;
    auto grid = ::mrpt::opengl::CGridPlaneXY::Create(
        static_cast<float>(box.min().x() - margin), static_cast<float>(box.max().x() + margin),
        static_cast<float>(box.min().y() - margin), static_cast<float>(box.max().y() + margin), 0.0f,
        static_cast<float>(std::max(1.0, margin / 2)));
    grid->setColor(0.6f, 0.6f, 0.6f, 0.5f);
    scene->insert(grid);
  }
  scene->insert(detail::path_lines(content.estimated_path, scene_names::estimated_path, 1.0f, 0.0f, 0.0f));
  if (!content.true_path.empty())
    scene->insert(detail::path_lines(content.true_path, scene_names::true_path, 0.0f, 0.0f, 0.0f));
  auto landmarks = ::mrpt::opengl::CSetOfObjects::Create();
  landmarks->setName(scene_names::landmarks);
  for (const auto& landmark : content.landmarks) {
    if (!landmark.mean.allFinite() || !landmark.cov.allFinite())
      throw invalid_input_error("landmark " + std::to_string(landmark.id) + ": mean or covariance contains NaN or Inf");
    landmarks->insert(detail::landmark_ellipse(landmark, options.quantile));
  }
  scene->insert(landmarks);
  if (!content.true_landmarks.empty())
    scene->insert(detail::point_cloud(content.true_landmarks, scene_names::true_landmarks, 0.0f, 0.6f, 0.0f, 5.0f));
  if (!content.particles.empty())
    scene->insert(detail::point_cloud(content.particles, scene_names::particles, 1.0f, 0.5f, 0.0f, 2.0f));
  return scene;
}

/// Writes the scene to `path` (MRPT's gzip-compressed `.3Dscene`); throws sextant::error on failure.
inline void write_scene(const std::string& path, const SceneContent& content, const SceneOptions& options = {}) {
  if (!make_scene(content, options)->saveToFile(path)) throw error(path + ": cannot write the 3D scene");
}

/// A landmark map (LandmarkEstimate<2> or <3>) as scene landmarks.
template <int M>
std::vector<SceneContent::Landmark> scene_landmarks(const std::vector<LandmarkEstimate<M>>& map) {
  static_assert(M == 2 || M == 3);
  std::vector<SceneContent::Landmark> out;
  for (const auto& l : map) {
    SceneContent::Landmark s;
    s.id = l.id;
    s.mean.head<M>() = l.mean;
    s.cov.topLeftCorner<M, M>() = l.cov;
    s.planar = M == 2;
    out.push_back(s);
  }
  return out;
}

}  // namespace sextant::mrpt_io
