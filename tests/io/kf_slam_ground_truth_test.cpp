#include "sextant/io/kf_slam_ground_truth.hpp"

#include <gtest/gtest.h>

#include "support/temp_path.hpp"

#include <filesystem>
#include <fstream>
#include <functional>

namespace sextant::io {
namespace {

class GroundTruthFile : public ::testing::Test {
 protected:
  std::filesystem::path path = test::unique_temp_path("gt_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
  void TearDown() override { std::filesystem::remove(path); }
  std::string error_of(const std::function<void()>& read) {
    try {
      read();
    } catch (const parse_error& e) {
      return e.what();
    }
    return "no error";
  }
};

TEST_F(GroundTruthFile, ReadsMapWithIdInLastColumnAndPathSkippingComments) {
  std::ofstream(path) << "% comment\n  0.5 7.5 0.1   5 0 0.0 3\n\n2.0 1.0 0.0 5 0 0 9\n";
  const auto map2 = read_kf_slam_landmarks<2>(path.string());
  ASSERT_EQ(map2.size(), 2u);
  EXPECT_EQ(map2.at(3), Eigen::Vector2d(0.5, 7.5));
  EXPECT_DOUBLE_EQ(read_kf_slam_landmarks<3>(path.string()).at(3).z(), 0.1);
  std::ofstream(path) << "% x y z yaw pitch roll\n0 0 0 0 0 0\n1 2 3 0.1 0.2 0.3\n";
  const auto poses = read_kf_slam_path(path.string());
  ASSERT_EQ(poses.size(), 2u);
  EXPECT_EQ(planar_path(poses)[1], Eigen::Vector3d(1, 2, 0.1));
}

TEST_F(GroundTruthFile, BadRowsNameFileAndLine) {
  const std::string p = path.string();
  std::ofstream(p) << "0 0 0 0 0 0\n1 2 x 0 0 0\n";
  EXPECT_NE(error_of([&] { read_kf_slam_path(p); }).find(p + ":2: 'x' is not a finite number"), std::string::npos);
  std::ofstream(p) << "0 0 0 0 0\n";
  EXPECT_NE(error_of([&] { read_kf_slam_path(p); }).find(p + ":1: expected 6 values"), std::string::npos);
  std::ofstream(p) << "1 2 0 5 0 0 4\n3 4 0 5 0 0 4\n";
  EXPECT_NE(error_of([&] { read_kf_slam_landmarks<2>(p); }).find(p + ":2: landmark 4 appears twice"), std::string::npos);
  std::ofstream(p) << "1 2 0 5 0 0 -1\n";
  EXPECT_NE(error_of([&] { read_kf_slam_landmarks<2>(p); }).find("non-negative integer"), std::string::npos);
  for (const char* id : {"2.5", "-3"}) {  // issue 15: fractional or negative ids (beyond 1e12: below)
    std::ofstream(p) << "1 2 0 5 0 0 " << id << "\n";
    EXPECT_NE(error_of([&] { read_kf_slam_landmarks<2>(p); }).find("non-negative integer below 2^53"), std::string::npos) << id;
  }
  // Issue 36: a finite number too large for the estimators' arithmetic (a map coordinate of 1e308 gave
  // inf errors in every row) is refused at its line, as are ids beyond it (6.1e19, 1e30).
  for (const char* row : {"1e308 2 0 5 0 0 4\n", "1 2 0 5 0 0 6.1e19\n", "1 2 0 5 0 0 1e30\n"}) {
    std::ofstream(p) << row;
    EXPECT_NE(error_of([&] { read_kf_slam_landmarks<2>(p); }).find(p + ":1: "), std::string::npos) << row;
    EXPECT_NE(error_of([&] { read_kf_slam_landmarks<2>(p); }).find("is beyond +-1e12"), std::string::npos) << row;
  }
  std::ofstream(p) << "0 0 0 0 0 0\n-2e13 0 0 0 0 0\n";
  EXPECT_NE(error_of([&] { read_kf_slam_path(p); }).find(p + ":2: '-2e13' is beyond +-1e12"), std::string::npos);
  std::ofstream(p) << "% nothing\n";
  EXPECT_NE(error_of([&] { read_kf_slam_landmarks<2>(p); }).find("no landmarks"), std::string::npos);
  EXPECT_NE(error_of([&] { read_kf_slam_path(p + ".missing"); }).find("cannot open file"), std::string::npos);
  // Issue 36: a directory where a file is expected said "no data rows".
  const auto folder = std::filesystem::path(p).parent_path() / "a_folder.txt";
  std::filesystem::create_directories(folder);
  EXPECT_NE(error_of([&] { read_kf_slam_path(folder.string()); }).find(folder.string() + ": is a directory, not a file"),
            std::string::npos);
  std::filesystem::remove(folder);
}

}  // namespace
}  // namespace sextant::io
