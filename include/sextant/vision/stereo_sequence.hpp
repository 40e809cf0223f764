#pragma once
/// \file A rectified stereo sequence on disk: <dir>/left/*.png and <dir>/right/*.png (the k-th
/// names in sorted order form pair k) and <dir>/calib.yaml, read and written with cv::FileStorage:
/// K (3x3, fx = fy: rectified), baseline [m], image_width and image_height [px], and optionally dt
/// [s] and the 12D camera's starting state and its standard deviations (initial_state,
/// initial_sigma: p, eta, v, omega as in models/euler_camera_12d.hpp). Every error names the file.

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "sextant/core/error.hpp"
#include "sextant/core/gaussian.hpp"
#include "sextant/models/euler_camera_12d.hpp"
#include "sextant/vision/stereo_triangulation.hpp"

namespace sextant::vision {

struct StereoCalibration {
  Eigen::Matrix3d K = Eigen::Matrix3d::Identity();
  double baseline = 0.0;  ///< m, the right camera along the left's +x
  int width = 0, height = 0;
  double dt = 1.0 / 15.0;  ///< s between frames
  std::optional<Eigen::Matrix<double, 12, 1>> initial_state, initial_sigma;

  StereoRig rig() const { return {K(0, 0), K(0, 2), K(1, 2), baseline}; }
};

namespace detail {

inline std::filesystem::path calibration_file(const std::filesystem::path& dir) { return dir / "calib.yaml"; }

inline cv::Mat as_cv_row(const Eigen::Matrix<double, 12, 1>& v) {
  cv::Mat m(1, 12, CV_64F);
  for (int i = 0; i < 12; ++i) m.at<double>(0, i) = v(i);
  return m;
}

/// An optional 12-vector: absent gives nothing; present but not 12 finite numbers is an error.
inline std::optional<Eigen::Matrix<double, 12, 1>> read_vector12(const cv::FileStorage& fs, const char* key,
                                                                const std::string& file) {
  const cv::FileNode node = fs[key];
  if (node.empty()) return std::nullopt;
  cv::Mat m;
  node >> m;
  if (m.total() != 12 || m.channels() != 1)
    throw parse_error(file + ": " + key + " must hold 12 numbers (p, eta, v, omega)");
  m.convertTo(m, CV_64F);
  Eigen::Matrix<double, 12, 1> out;
  for (int i = 0; i < 12; ++i) out(i) = m.at<double>(i);
  if (!out.allFinite()) throw parse_error(file + ": " + key + " has NaN or Inf");
  return out;
}

inline std::vector<std::filesystem::path> images_in(const std::filesystem::path& dir) {
  if (!std::filesystem::is_directory(dir)) throw parse_error(dir.string() + ": no such directory");
  std::vector<std::filesystem::path> out;
  for (const auto& entry : std::filesystem::directory_iterator(dir))
    if (entry.is_regular_file() && entry.path().extension() == ".png") out.push_back(entry.path());
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace detail

/// Reads <dir>/calib.yaml. Throws parse_error naming the file for a missing or unreadable file, K
/// missing or not 3x3 with fx = fy, a baseline missing or not positive, an image size missing or
/// not positive, or a dt that is not positive.
inline StereoCalibration read_calibration(const std::filesystem::path& dir) {
  const std::string file = detail::calibration_file(dir).string();
  if (!std::filesystem::is_regular_file(file)) throw parse_error(file + ": no such file (the stereo calibration)");
  cv::FileStorage fs;
  try {
    if (!fs.open(file, cv::FileStorage::READ)) throw parse_error(file + ": cannot be read as YAML");
  } catch (const cv::Exception& e) {
    throw parse_error(file + ": cannot be read as YAML (" + e.msg + ")");
  }
  StereoCalibration c;
  cv::Mat K;
  fs["K"] >> K;
  if (K.empty()) throw parse_error(file + ": no K (the 3x3 camera matrix)");
  if (K.rows != 3 || K.cols != 3 || K.channels() != 1) throw parse_error(file + ": K is not 3x3");
  K.convertTo(K, CV_64F);
  for (int r = 0; r < 3; ++r)
    for (int col = 0; col < 3; ++col) c.K(r, col) = K.at<double>(r, col);
  if (!c.K.allFinite() || !(c.K(0, 0) > 0.0) || std::abs(c.K(0, 0) - c.K(1, 1)) > 1e-6 * c.K(0, 0))
    throw parse_error(file + ": K needs finite fx = fy > 0 (a rectified pair)");
  if (fs["baseline"].empty()) throw parse_error(file + ": no baseline");
  fs["baseline"] >> c.baseline;
  if (!(c.baseline > 0.0) || !std::isfinite(c.baseline)) throw parse_error(file + ": baseline must be > 0 m");
  if (fs["image_width"].empty() || fs["image_height"].empty())
    throw parse_error(file + ": no image_width or image_height");
  fs["image_width"] >> c.width;
  fs["image_height"] >> c.height;
  if (c.width <= 0 || c.height <= 0) throw parse_error(file + ": image size must be positive");
  if (!fs["dt"].empty()) fs["dt"] >> c.dt;
  if (!(c.dt > 0.0) || !std::isfinite(c.dt)) throw parse_error(file + ": dt must be > 0 s");
  c.initial_state = detail::read_vector12(fs, "initial_state", file);
  c.initial_sigma = detail::read_vector12(fs, "initial_sigma", file);
  if (c.initial_sigma && !(c.initial_sigma->array() > 0.0).all())
    throw parse_error(file + ": initial_sigma must be positive");
  return c;
}

inline void write_calibration(const std::filesystem::path& dir, const StereoCalibration& c) {
  std::filesystem::create_directories(dir);
  const std::string file = detail::calibration_file(dir).string();
  cv::FileStorage fs(file, cv::FileStorage::WRITE);
  if (!fs.isOpened()) throw invalid_input_error(file + ": cannot be written");
  cv::Mat K(3, 3, CV_64F);
  for (int r = 0; r < 3; ++r)
    for (int col = 0; col < 3; ++col) K.at<double>(r, col) = c.K(r, col);
  fs << "K" << K << "baseline" << c.baseline << "image_width" << c.width << "image_height" << c.height << "dt" << c.dt;
  if (c.initial_state) fs << "initial_state" << detail::as_cv_row(*c.initial_state);
  if (c.initial_sigma) fs << "initial_sigma" << detail::as_cv_row(*c.initial_sigma);
}

/// Writes pair k as left/%06d.png and right/%06d.png (8-bit grayscale, lossless).
inline void write_stereo_pair(const std::filesystem::path& dir, std::size_t k, const cv::Mat& left, const cv::Mat& right) {
  char name[32];
  std::snprintf(name, sizeof name, "%06zu.png", k);
  for (const auto& [side, image] : {std::pair{"left", &left}, std::pair{"right", &right}}) {
    std::filesystem::create_directories(dir / side);
    const auto file = (dir / side / name).string();
    if (!cv::imwrite(file, *image)) throw invalid_input_error(file + ": cannot be written");
  }
}

/// The 12D camera's starting estimate for a sequence: the calibration's initial_state and
/// initial_sigma where given, else the camera at the origin at rest, known to 1 mm and 1 mrad, with
/// velocity and rate unknown to 0.5 m/s and 1 rad/s (a handheld camera).
inline Gaussian<Vector12d, 12> initial_camera_estimate(const StereoCalibration& c) {
  Gaussian<Vector12d, 12> prior;
  prior.mean = c.initial_state.value_or(Vector12d::Zero());
  Vector12d sigma;
  sigma << Eigen::Vector3d::Constant(1e-3), Eigen::Vector3d::Constant(1e-3), Eigen::Vector3d::Constant(0.5),
      Eigen::Vector3d::Constant(1.0);
  if (c.initial_sigma) sigma = *c.initial_sigma;
  prior.cov = sigma.cwiseAbs2().asDiagonal();
  return prior;
}

/// The pairs and calibration of a sequence directory; images are read one pair at a time.
class StereoSequence {
 public:
  /// Throws parse_error for a missing directory or calibration, no images, or left and right counts that differ.
  explicit StereoSequence(const std::filesystem::path& dir)
      : calibration_(read_calibration(dir)), left_(detail::images_in(dir / "left")), right_(detail::images_in(dir / "right")) {
    if (left_.empty()) throw parse_error((dir / "left").string() + ": no .png images");
    if (left_.size() != right_.size())
      throw parse_error(dir.string() + ": " + std::to_string(left_.size()) + " left images but " +
                        std::to_string(right_.size()) + " right images");
  }

  std::size_t size() const { return left_.size(); }
  const StereoCalibration& calibration() const { return calibration_; }

  /// Pair k as 8-bit grayscale. Throws parse_error naming the file when an image cannot be read or
  /// its size is not the calibration's.
  std::pair<cv::Mat, cv::Mat> load(std::size_t k) const { return {read(left_.at(k)), read(right_.at(k))}; }

 private:
  cv::Mat read(const std::filesystem::path& file) const {
    cv::Mat image = cv::imread(file.string(), cv::IMREAD_GRAYSCALE);
    if (image.empty()) throw parse_error(file.string() + ": cannot be read as an image");
    if (image.cols != calibration_.width || image.rows != calibration_.height)
      throw parse_error(file.string() + ": " + std::to_string(image.cols) + "x" + std::to_string(image.rows) +
                        " pixels, the calibration says " + std::to_string(calibration_.width) + "x" +
                        std::to_string(calibration_.height));
    return image;
  }

  StereoCalibration calibration_;
  std::vector<std::filesystem::path> left_, right_;
};

}  // namespace sextant::vision
