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
#include <opencv2/core/utils/logger.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "sextant/core/error.hpp"
#include "sextant/core/gaussian.hpp"
#include "sextant/io/parse_number.hpp"
#include "sextant/models/euler_camera_12d.hpp"
#include "sextant/vision/calibration_yaml_lint.hpp"
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

/// Whether `node` is an opencv-matrix of rows x cols, read off its header before OpenCV allocates
/// the matrix (a header of 2^31 rows would otherwise allocate first).
inline bool is_matrix_of(const cv::FileNode& node, int rows, int cols) {
  if (!node.isMap() || !node["rows"].isInt() || !node["cols"].isInt()) return false;
  return static_cast<int>(node["rows"]) == rows && static_cast<int>(node["cols"]) == cols;
}

/// An optional 12-vector: absent gives nothing; present but not 12 finite numbers is an error.
inline std::optional<Eigen::Matrix<double, 12, 1>> read_vector12(const cv::FileStorage& fs, const char* key,
                                                                const std::string& file) {
  const cv::FileNode node = fs[key];
  if (node.empty()) return std::nullopt;
  Eigen::Matrix<double, 12, 1> out;
  if (node.isSeq()) {  // a plain YAML list [a, b, ...]
    if (node.size() != 12) throw parse_error(file + ": " + key + " must hold 12 numbers (p, eta, v, omega)");
    for (int i = 0; i < 12; ++i) {
      if (!node[i].isReal() && !node[i].isInt()) throw parse_error(file + ": " + key + " must hold 12 numbers");
      out(i) = static_cast<double>(node[i]);
    }
  } else {  // an opencv-matrix (what write_calibration writes)
    if (!is_matrix_of(node, 1, 12) && !is_matrix_of(node, 12, 1))
      throw parse_error(file + ": " + key + " must hold 12 numbers (p, eta, v, omega)");
    cv::Mat m;
    node >> m;
    if (m.total() != 12 || m.channels() != 1)
      throw parse_error(file + ": " + key + " must hold 12 numbers (p, eta, v, omega)");
    m.convertTo(m, CV_64F);
    for (int i = 0; i < 12; ++i) out(i) = m.at<double>(i);
  }
  if (!out.allFinite()) throw parse_error(file + ": " + key + " has NaN or Inf");
  return out;
}

inline std::vector<std::filesystem::path> images_in(const std::filesystem::path& dir) {
  if (!std::filesystem::is_directory(dir)) throw parse_error(dir.string() + ": no such directory");
  std::vector<std::filesystem::path> out;
  for (const auto& entry : std::filesystem::directory_iterator(dir))
    if (entry.path().extension() == ".png") out.push_back(entry.path());  // one that is no file fails when read
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace detail

/// Reads <dir>/calib.yaml. Throws parse_error naming the file for a missing or unreadable file, K
/// missing or not 3x3 with fx = fy, a baseline missing or not positive, an image size missing or
/// not positive, or a dt that is not positive.
namespace detail {
/// Every number of the calibration within +-1e12 (io::kMaxDataMagnitude) and the image no larger
/// than 2^16 pixels a side: a baseline of 1e308 failed far away, in a filter, without the file.
inline void require_plausible(const StereoCalibration& c, const std::string& file) {
  auto check = [&](double value, const char* what) {
    if (std::abs(value) > io::kMaxDataMagnitude)
      throw parse_error(file + ": " + what + " is beyond +-1e12, the largest magnitude sextant reads");
  };
  for (int i = 0; i < 9; ++i) check(c.K(i / 3, i % 3), "an entry of K");
  check(c.baseline, "baseline");
  check(c.dt, "dt");
  for (const auto& v : {c.initial_state, c.initial_sigma})
    if (v)
      for (double x : *v) check(x, "an entry of initial_state or initial_sigma");
  if (c.width > 65536 || c.height > 65536) throw parse_error(file + ": image size above 65536 pixels a side");
}
}  // namespace detail

inline StereoCalibration read_calibration_from(const cv::FileStorage& fs, const std::string& file);

inline StereoCalibration read_calibration(const std::filesystem::path& dir) {
  const std::string file = detail::calibration_file(dir).string();
  if (std::filesystem::is_directory(file)) throw parse_error(file + ": is a directory, not a file (the stereo calibration)");
  if (!std::filesystem::is_regular_file(file)) throw parse_error(file + ": no such file (the stereo calibration)");
  detail::lint_calibration_yaml(file);  // before OpenCV's parser, which can loop forever on a malformed file
  cv::FileStorage fs;
  bool opened = false;
  try {  // OpenCV's parser throws cv::Exception, and on some malformed files std::length_error
    opened = fs.open(file, cv::FileStorage::READ);
  } catch (const std::exception& e) {
    throw parse_error(file + ": cannot be read as YAML (" + io::printable_excerpt(e.what(), 200) + ")");
  }
  if (!opened) throw parse_error(file + ": cannot be read as YAML");
  try {  // OpenCV asserts on a node of the wrong kind (a list where a map is read): an error of the file
    return read_calibration_from(fs, file);
  } catch (const error&) {
    throw;
  } catch (const std::exception& e) {
    throw parse_error(file + ": " + io::printable_excerpt(e.what(), 200));
  }
}

/// The calibration's keys (read_calibration).
inline StereoCalibration read_calibration_from(const cv::FileStorage& fs, const std::string& file) {
  StereoCalibration c;
  if (!fs["K"].empty() && !detail::is_matrix_of(fs["K"], 3, 3)) throw parse_error(file + ": K is not 3x3");
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
  detail::require_plausible(c, file);
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
    for (std::size_t k = 0; k < left_.size(); ++k)  // a pair shares its name (KITTI, EuRoC, ours)
      if (left_[k].filename() != right_[k].filename())
        throw parse_error(dir.string() + ": pair " + std::to_string(k) + " is left/" + left_[k].filename().string() +
                          " and right/" + right_[k].filename().string() + ": the two images of a pair must share a name");
  }

  std::size_t size() const { return left_.size(); }
  const StereoCalibration& calibration() const { return calibration_; }

  /// Pair k as 8-bit grayscale. Throws parse_error naming the file when an image cannot be read or
  /// its size is not the calibration's.
  std::pair<cv::Mat, cv::Mat> load(std::size_t k) const { return {read(left_.at(k)), read(right_.at(k))}; }

 private:
  cv::Mat read(const std::filesystem::path& file) const {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(file, ec)) throw parse_error(file.string() + ": cannot be read as an image (not a file)");
    // OpenCV logs a warning of its own for a file no decoder knows; the error below says it once.
    const auto level = cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_ERROR);
    cv::Mat image;
    try {
      image = cv::imread(file.string(), cv::IMREAD_GRAYSCALE);
    } catch (const cv::Exception& e) {
      cv::utils::logging::setLogLevel(level);
      throw parse_error(file.string() + ": cannot be read as an image (" + io::printable_excerpt(e.msg, 200) + ")");
    }
    cv::utils::logging::setLogLevel(level);
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
