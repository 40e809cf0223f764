#include "sextant/io/isam_reader.hpp"
#include "sextant/io/isam_dataset.hpp"

#include <gtest/gtest.h>

#include "support/temp_path.hpp"

#include <filesystem>
#include <fstream>
#include <vector>

namespace sextant::io {
namespace {

std::vector<std::string>& written_files() {
  static std::vector<std::string> files;
  return files;
}

/// Removes every file write_file wrote when the test program ends.
struct RemoveWrittenFiles : ::testing::Environment {
  void TearDown() override {
    for (const auto& path : written_files()) std::filesystem::remove(path);
  }
};
const auto* const kRemoveWrittenFiles = ::testing::AddGlobalTestEnvironment(new RemoveWrittenFiles);

std::string write_file(const std::string& name, const std::string& text) {
  const auto path = test::unique_temp_path("isam_" + name + ".txt").string();
  std::ofstream(path) << text;
  written_files().push_back(path);
  return path;
}

TEST(IsamReader, ReadsSquareRootInformationRecords) {
  const auto path = write_file("sqrt", "EDGE2 0 1 1 0 0.5 50 0 0 50 0 100\n"
                                       "LANDMARK 1 7 2 -1 10 0 10\n"
                                       "# a comment\n\n"
                                       "EDGE2 1 2 1 0 0 50 0 0 50 0 100\n");
  const auto data = read_isam_2d(path, IsamNoise::square_root_information);
  ASSERT_EQ(data.steps.size(), 2u);
  EXPECT_EQ(data.pose_ids, (std::vector<long long>{0, 1, 2}));
  EXPECT_TRUE(data.steps[0].control.delta.isApprox(Eigen::Vector3d(1.0, 0.0, 0.5)));
  EXPECT_TRUE(data.steps[0].control.cov.isApprox(Eigen::Vector3d(1.0 / 2500, 1.0 / 2500, 1.0 / 10000).asDiagonal().toDenseMatrix()));
  ASSERT_EQ(data.steps[0].observations.size(), 1u);
  EXPECT_EQ(data.steps[0].observations[0].landmark_id, 7u);
  EXPECT_TRUE(data.landmark_cov.isApprox(0.01 * Eigen::Matrix2d::Identity()));
}

TEST(IsamReader, ReadsCovarianceRecordsAndObservationsOfTheFirstPose) {
  const auto path = write_file("cov", "LANDMARK 4 5 11.5 -3.2 0.4 0.1 0.4\n"
                                      "ODOMETRY 4 6 0.08 0 0.001 0.0001 0 0 4e-06 0 4e-06\n");
  const auto data = read_isam_2d(path, IsamNoise::covariance);
  EXPECT_EQ(data.pose_ids, (std::vector<long long>{4, 6}));
  ASSERT_EQ(data.initial_observations.size(), 1u);
  EXPECT_EQ(data.landmark_cov(0, 1), 0.1);
  EXPECT_EQ(data.steps[0].control.cov(1, 1), 4e-06);
  // Issue 36: a covariance of 1e-300 was accepted and failed in a filter without the file and line.
  const auto tiny = write_file("tiny_cov", "LANDMARK 4 5 11.5 -3.2 0.4 0.1 0.4\n"
                                           "ODOMETRY 4 6 0.08 0 0.001 1e-300 0 0 4e-06 0 4e-06\n");
  try {
    read_isam_2d(tiny, IsamNoise::covariance);
    ADD_FAILURE() << "a variance of 1e-300 was read";
  } catch (const parse_error& e) {
    EXPECT_NE(std::string(e.what()).find(tiny + ":2: a variance below 1e-24"), std::string::npos) << e.what();
  }
}

TEST(IsamReader, ImplausibleStepsAndLandmarkDistancesAreUsedAndListedWithFileAndLine) {
  // Issue 36: an odometry step of kilometres or a landmark a kilometre away is legal but no ground
  // vehicle's; it is read and listed, the first five in full and a count of the rest.
  std::string text = "EDGE2 0 1 1 0 0 50 0 0 50 0 100\nLANDMARK 1 7 2000 0 10 0 10\n";
  for (int k = 1; k <= 6; ++k)
    text += "EDGE2 " + std::to_string(k) + " " + std::to_string(k + 1) + " 300 0 0 50 0 0 50 0 100\n";
  const auto path = write_file("implausible", text);
  const auto data = read_isam_2d(path, IsamNoise::square_root_information);
  EXPECT_EQ(data.steps.size(), 7u);
  EXPECT_EQ(data.implausible.count, 7u);
  const auto warnings = data.implausible.warnings();
  ASSERT_EQ(warnings.size(), 6u);
  EXPECT_EQ(warnings[0], "warning: " + path + ":2: landmark at a distance of 2000 m is beyond the plausible 1000 m (used as given)");
  EXPECT_EQ(warnings[1], "warning: " + path + ":3: odometry step of 300 m is beyond the plausible 100 m (used as given)");
  EXPECT_EQ(warnings[5], "warning: and 2 more implausible values");
}

TEST(IsamReader, GroundTruthComposesOdometryAndLandmarks) {
  const auto path = write_file("truth", "EDGE2 0 1 1 0 1.5707963267948966 50 0 0 50 0 100\n"
                                        "LANDMARK 1 3 2 0 10 0 10\n");
  const auto truth = ground_truth_from_noise_free(read_isam_2d(path, IsamNoise::square_root_information));
  EXPECT_TRUE(truth.poses[1].isApprox(Eigen::Vector3d(1.0, 0.0, 1.5707963267948966)));
  EXPECT_TRUE(truth.landmarks.at(3).isApprox(Eigen::Vector2d(1.0, 2.0)));
}

struct Malformed {
  const char* name;
  const char* text;
  const char* message;  // what the error must say, after "file:line"
};

class IsamReaderRejects : public ::testing::TestWithParam<Malformed> {};

TEST_P(IsamReaderRejects, NamingTheLine) {
  const auto& c = GetParam();
  const auto path = write_file(c.name, c.text);
  try {
    read_isam_2d(path, IsamNoise::square_root_information);
    FAIL() << "expected parse_error";
  } catch (const parse_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(path + ":2:"), std::string::npos) << what;
    EXPECT_NE(what.find(c.message), std::string::npos) << what;
  }
}

INSTANTIATE_TEST_SUITE_P(
    MalformedFiles, IsamReaderRejects,
    ::testing::Values(
        Malformed{"tag", "EDGE2 0 1 1 0 0 50 0 0 50 0 100\nVERTEX 1 2 3\n", "unknown record 'VERTEX'"},
        Malformed{"count", "EDGE2 0 1 1 0 0 50 0 0 50 0 100\nEDGE2 1 2 1 0 0 50 0 0 50 0\n", "needs 11 values, found 10"},
        Malformed{"number", "EDGE2 0 1 1 0 0 50 0 0 50 0 100\nLANDMARK 1 2 x 0 10 0 10\n", "'x' is not a finite number"},
        Malformed{"nan", "EDGE2 0 1 1 0 0 50 0 0 50 0 100\nLANDMARK 1 2 nan 0 10 0 10\n", "'nan' is not a finite number"},
        Malformed{"chain", "EDGE2 0 1 1 0 0 50 0 0 50 0 100\nEDGE2 5 6 1 0 0 50 0 0 50 0 100\n", "does not continue the chain"},
        Malformed{"old_pose", "EDGE2 0 1 1 0 0 50 0 0 50 0 100\nLANDMARK 0 2 1 0 10 0 10\n", "newest pose is 1"},
        Malformed{"singular", "EDGE2 0 1 1 0 0 50 0 0 50 0 100\nEDGE2 1 2 1 0 0 50 0 0 0 0 100\n", "singular"},
        Malformed{"noise", "LANDMARK 0 1 1 0 10 0 10\nLANDMARK 0 2 1 0 20 0 20\n", "landmark noise differs"},
        Malformed{"twice", "LANDMARK 0 1 1 0 10 0 10\nLANDMARK 0 1 1 0 10 0 10\n", "seen twice"},
        // Identifiers that a cast from double would truncate or make undefined (issue 15's UBSan finding).
        // (Since issue 36 an id beyond 1e12 is refused as a number before it is taken for an id.)
        Malformed{"huge_landmark_id", "EDGE2 0 1 1 0 0 50 0 0 50 0 100\nLANDMARK 1 9e15 1 0 10 0 10\n",
                  "'9e15' is beyond +-1e12"},
        // Issue 36: finite numbers too large for the estimators' arithmetic were reported by a filter
        // ("EKF motion update overflowed") without the file and line.
        Malformed{"huge_motion", "EDGE2 0 1 1 0 0 50 0 0 50 0 100\nEDGE2 1 2 1e308 0 0 50 0 0 50 0 100\n",
                  "'1e308' is beyond +-1e12"},
        Malformed{"huge_landmark", "EDGE2 0 1 1 0 0 50 0 0 50 0 100\nLANDMARK 1 2 1e308 0 10 0 10\n",
                  "'1e308' is beyond +-1e12"},
        Malformed{"huge_noise", "EDGE2 0 1 1 0 0 50 0 0 50 0 100\nEDGE2 1 2 1 0 0 1e308 0 0 50 0 100\n",
                  "'1e308' is beyond +-1e12"},
        Malformed{"huge_id", "EDGE2 0 1 1 0 0 50 0 0 50 0 100\nLANDMARK 1 6.1e19 1 0 10 0 10\n", "is beyond +-1e12"},
        Malformed{"negative_pose_id", "EDGE2 0 1 1 0 0 50 0 0 50 0 100\nEDGE2 -1 2 1 0 0 50 0 0 50 0 100\n",
                  "pose id must be a non-negative integer"},
        Malformed{"huge_pose_id", "EDGE2 0 1 1 0 0 50 0 0 50 0 100\nLANDMARK 9e15 2 1 0 10 0 10\n",
                  "'9e15' is beyond +-1e12"},
        Malformed{"fractional_landmark_id", "EDGE2 0 1 1 0 0 50 0 0 50 0 100\nLANDMARK 1 2.5 1 0 10 0 10\n",
                  "landmark id must be a non-negative integer below 2^53"},
        Malformed{"fractional_pose_id", "EDGE2 0 1 1 0 0 50 0 0 50 0 100\nEDGE2 1.7 2 1 0 0 50 0 0 50 0 100\n",
                  "pose id must be a non-negative integer"},
        // Issue 36: square-root information that is all zero, or so small or so large that the
        // covariance it stands for is no usable noise (variance 1e300 or 1e-300), is refused at its line.
        Malformed{"zero_square_root_information", "EDGE2 0 1 1 0 0 50 0 0 50 0 100\nEDGE2 1 2 1 0 0 0 0 0 0 0 0\n",
                  "square-root information is singular"},
        Malformed{"zero_landmark_information", "EDGE2 0 1 1 0 0 50 0 0 50 0 100\nLANDMARK 1 2 1 0 0 0 0\n",
                  "square-root information is singular"},
        Malformed{"vanishing_information", "EDGE2 0 1 1 0 0 50 0 0 50 0 100\nEDGE2 1 2 1 0 0 1e-150 0 0 50 0 100\n",
                  "a variance above 1e24"}),
    [](const auto& info) { return std::string(info.param.name); });

TEST(IsamReader, MissingOrEmptyFile) {
  EXPECT_THROW(read_isam_2d("/nonexistent/file.txt", IsamNoise::covariance), parse_error);
  EXPECT_THROW(read_isam_2d(write_file("empty", "# nothing\n"), IsamNoise::covariance), parse_error);
}

/// A directory of its own, removed at the end of the test, for files whose names must match.
struct TempDirectory {
  std::filesystem::path path = test::unique_temp_path("isam_dataset");
  TempDirectory() { std::filesystem::create_directories(path); }
  ~TempDirectory() { std::filesystem::remove_all(path); }
  std::string write(const std::string& name, const std::string& text) const {
    std::ofstream((path / name).string()) << text;
    return (path / name).string();
  }
};

TEST(IsamDataset, SightingsBeforeTheFirstOdometryComeInAStillStepAndTheCompanionIsTheTruth) {
  const TempDirectory dir;
  const auto path = dir.write("trees.txt", "LANDMARK 0 3 1 0.1 10 0 10\n"
                                           "EDGE2 0 1 1 0 0 50 0 0 50 0 100\n"
                                           "LANDMARK 1 3 0.1 0 10 0 10\n");
  EXPECT_FALSE(read_isam_dataset(path).has_ground_truth()) << "no companion yet";
  dir.write("trees_groundtruth.txt", "LANDMARK 0 3 1 0 10 0 10\n"
                                     "EDGE2 0 1 1 0 0 50 0 0 50 0 100\n"
                                     "LANDMARK 1 3 0 0 10 0 10\n");
  EXPECT_EQ(detect_isam_noise(path), IsamNoise::square_root_information);
  const auto data = read_isam_dataset(path);
  ASSERT_EQ(data.steps.size(), 2u);
  EXPECT_EQ(data.steps[0].control.delta, Eigen::Vector3d::Zero()) << "the still step";
  ASSERT_EQ(data.steps[0].observations.size(), 1u);
  EXPECT_EQ(data.steps[0].observations[0].landmark_id, 3u);
  EXPECT_TRUE(data.steps[1].control.delta.isApprox(Eigen::Vector3d(1, 0, 0)));
  EXPECT_TRUE(data.sensor.Q.isApprox(0.01 * Eigen::Matrix2d::Identity())) << "sqrt information 10 is variance 0.01";
  ASSERT_TRUE(data.has_ground_truth());
  ASSERT_EQ(data.true_poses.size(), 3u) << "one pose per step and the start";
  EXPECT_EQ(data.true_poses[1], data.true_poses[0]);
  EXPECT_TRUE(data.true_poses[2].isApprox(Eigen::Vector3d(1, 0, 0)));
  EXPECT_TRUE(data.true_landmarks.at(3).isApprox(Eigen::Vector2d(1, 0)));
}

TEST(IsamDataset, NoiseFormIsReadOffTheRecordsAndAMismatchedCompanionIsAnError) {
  const TempDirectory dir;
  const auto gtsam = dir.write("park.txt", "ODOMETRY 0 1 1 0 0 0.01 0 0 0.01 0 0.001\nLANDMARK 1 4 2 1 0.1 0 0.1\n");
  EXPECT_EQ(detect_isam_noise(gtsam), IsamNoise::covariance);
  EXPECT_TRUE(read_isam_dataset(gtsam).sensor.Q.isApprox(0.1 * Eigen::Matrix2d::Identity()));
  const auto path = dir.write("run.txt", "EDGE2 0 1 1 0 0 50 0 0 50 0 100\n");
  const auto companion = dir.write("run_groundtruth.txt", "EDGE2 0 1 1 0 0 50 0 0 50 0 100\nEDGE2 1 2 1 0 0 50 0 0 50 0 100\n");
  try {
    read_isam_dataset(path);
    FAIL() << "a companion with more odometry was accepted";
  } catch (const parse_error& e) {
    EXPECT_NE(std::string(e.what()).find(companion + ": 2 odometry records, but"), std::string::npos) << e.what();
  }
  const auto landmarks_only = dir.write("empty.txt", "# nothing\n");
  EXPECT_THROW(detect_isam_noise(landmarks_only), parse_error);
}

}  // namespace
}  // namespace sextant::io
