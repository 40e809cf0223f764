#include "sextant/io/mrclam_reader.hpp"

#include <gtest/gtest.h>
#include <sys/resource.h>

#include <fstream>
#include <numbers>

#include "../support/shared_data.hpp"
#include "../support/temp_path.hpp"

namespace sextant::io {
namespace {

namespace fs = std::filesystem;

/// A hand-made data set with one robot: subjects 1-5 robots, 6 and 7 landmarks.
class MrclamFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = test::unique_temp_path(std::string("mrclam_") + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
    write("Barcodes.dat", "# Subject # Barcode #\n 1 5\n 2 14\n 3 41\n 4 32\n 5 23\n 6 63\n 7 81\n");
    write("Landmark_Groundtruth.dat", "# header\n 6 1.0 2.0 0.0001 0.0001\n 7 -3.0 0.5 0.0001 0.0001\n");
    // v = 1 m/s for 1 s, then 0.5 m/s with w = 0.2 rad/s; one repeated time stamp.
    write("Robot1_Odometry.dat", "# t v w\n100.0 1.0 0.0\n100.5 1.0 0.0\n101.0 0.5 0.2\n101.0 0.5 0.2\n103.0 0.0 0.0\n");
    write("Robot1_Groundtruth.dat", "# t x y h\n99.0 0.0 0.0 3.0\n101.0 2.0 0.0 -3.0\n104.0 5.0 0.0 -3.0\n");
    // before the run; robot 2 (barcode 14); unknown barcode 99; landmark 6 twice at one time; 7.
    write("Robot1_Measurement.dat",
          "# t barcode r b\n99.5 63 1.0 0.0\n100.3 14 2.0 0.1\n100.3 99 2.0 0.1\n100.3 63 2.2 0.3\n100.3 63 2.3 0.3\n"
          "101.1 81 4.0 -0.5\n");
  }
  void TearDown() override { fs::remove_all(dir_); }
  void write(const std::string& name, const std::string& text) { std::ofstream(dir_ / name) << text; }

  fs::path dir_;
};

TEST_F(MrclamFiles, CutsStepsAtMeasurementsAndAtMostMaxStepAndAveragesTheOdometry) {
  const auto run = read_mrclam(dir_.string(), 1, {.max_step = 0.5});
  EXPECT_DOUBLE_EQ(run.start_time, 100.0);
  // 100 -> 100.3 (measurement) -> 100.7 -> 101.1 (measurement) -> four steps of 0.475 s -> 103.0.
  ASSERT_EQ(run.steps.size(), 7u);
  EXPECT_NEAR(run.steps[0].dt, 0.3, 1e-12);
  EXPECT_NEAR(run.steps[1].dt, 0.4, 1e-12);  // 100.3 -> 101.1 in two equal pieces
  EXPECT_NEAR(run.step_times.back(), 3.0, 1e-12);
  ASSERT_EQ(run.true_poses.size(), run.steps.size() + 1);
  for (const auto& step : run.steps) EXPECT_LE(step.dt, 0.5 + 1e-12);
  // 100.7 -> 101.1: 0.3 s at v = 1, then 0.1 s at v = 0.5, w = 0.2.
  EXPECT_NEAR(run.steps[2].control.v, (0.3 * 1.0 + 0.1 * 0.5) / 0.4, 1e-12);
  EXPECT_NEAR(run.steps[2].control.w, 0.1 * 0.2 / 0.4, 1e-12);
  // Vicon halfway between (0,0,3) and (2,0,-3): the heading goes the short way through pi.
  EXPECT_NEAR(run.prior.mean(0), 1.0, 1e-12);
  EXPECT_NEAR(std::abs(run.prior.mean(2)), std::numbers::pi, 1e-12);
  EXPECT_NEAR(run.true_poses.back()(0), 4.0, 1e-12);
}

TEST_F(MrclamFiles, DropsRobotsUnknownBarcodesAndRepeatsAndCountsThem) {
  const auto run = read_mrclam(dir_.string(), 1, {.max_step = 0.5});
  ASSERT_EQ(run.steps[0].observations.size(), 1u);
  EXPECT_EQ(run.steps[0].observations[0].landmark_id, 6u);
  EXPECT_DOUBLE_EQ(run.steps[0].observations[0].z(0), 2.2);
  ASSERT_EQ(run.steps[2].observations.size(), 1u);
  EXPECT_EQ(run.steps[2].observations[0].landmark_id, 7u);
  EXPECT_EQ(run.counts.measurements, 2u);
  EXPECT_EQ(run.counts.robot_sightings, 1u);
  EXPECT_EQ(run.counts.unknown_barcodes, 1u);
  EXPECT_EQ(run.counts.repeated_in_step, 1u);
  EXPECT_EQ(run.counts.outside_run, 1u);
  EXPECT_EQ(run.true_landmarks.size(), 2u);
}

TEST_F(MrclamFiles, ImplausibleVelocitiesAndRangesAreUsedAndListedWithFileAndLine) {
  // Issue 36: legal numbers that no small robot or camera gives (50 m/s, 20 rad/s, a 90 m range)
  // were used without a word.
  EXPECT_EQ(read_mrclam(dir_.string(), 1).implausible.count, 0u);  // the plain files: nothing to say
  write("Robot1_Odometry.dat", "# t v w\n100.0 50.0 0.0\n100.5 1.0 20.0\n101.0 0.5 0.2\n103.0 0.0 0.0\n");
  write("Robot1_Measurement.dat", "# t barcode r b\n100.3 63 90.0 0.3\n101.1 81 4.0 -0.5\n");
  const auto run = read_mrclam(dir_.string(), 1);
  EXPECT_EQ(run.counts.measurements, 2u);  // used as given
  EXPECT_EQ(run.implausible.count, 3u);
  const auto warnings = run.implausible.warnings();
  ASSERT_EQ(warnings.size(), 3u);
  const std::string odometry = (dir_ / "Robot1_Odometry.dat").string(), measurements = (dir_ / "Robot1_Measurement.dat").string();
  EXPECT_EQ(warnings[0], "warning: " + odometry + ":2: speed 50 m/s is beyond the plausible 2 m/s (used as given)");
  EXPECT_EQ(warnings[1], "warning: " + odometry + ":3: turn rate 20 rad/s is beyond the plausible 6.28319 rad/s (used as given)");
  EXPECT_EQ(warnings[2], "warning: " + measurements + ":2: range 90 m is beyond the plausible 30 m (used as given)");
}

TEST_F(MrclamFiles, MalformedFilesNameFileAndLine) {
  const auto message = [&] {
    try {
      read_mrclam(dir_.string(), 1);
    } catch (const parse_error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  write("Robot1_Odometry.dat", "# t v w\n100.0 1.0 0.0\n100.5 1.0\n");
  EXPECT_NE(message().find("Robot1_Odometry.dat:3: expected 3 values"), std::string::npos) << message();
  write("Robot1_Odometry.dat", "100.0 1.0 0.0\n99.0 1.0 nan\n");
  EXPECT_NE(message().find("Robot1_Odometry.dat:2: 'nan' is not a finite number"), std::string::npos) << message();
  write("Robot1_Odometry.dat", "100.0 1.0 0.0\n99.0 1.0 0.0\n");
  EXPECT_NE(message().find("Robot1_Odometry.dat:2: time 99"), std::string::npos) << message();
  write("Robot1_Odometry.dat", "100.0 1.0 0.0\n103.0 1.0 0.0\n");
  write("Robot1_Measurement.dat", "100.3 63.5 2.0 0.1\n");
  EXPECT_NE(message().find("Robot1_Measurement.dat:1: subject and barcode"), std::string::npos) << message();
  write("Robot1_Measurement.dat", "100.3 63 -2.0 0.1\n");
  EXPECT_NE(message().find("Robot1_Measurement.dat:1: range must be positive"), std::string::npos) << message();
  write("Robot1_Measurement.dat", "");
  EXPECT_NE(message().find("Robot1_Measurement.dat: no data rows"), std::string::npos) << message();
  write("Robot1_Odometry.dat", "100.0 1e308 0.0\n103.0 1.0 0.0\n");  // issue 36: a velocity of 1e308
  EXPECT_NE(message().find("Robot1_Odometry.dat:1: '1e308' is beyond +-1e12"), std::string::npos) << message();
  fs::remove(dir_ / "Barcodes.dat");
  EXPECT_NE(message().find("Barcodes.dat: cannot open file"), std::string::npos) << message();
  EXPECT_THROW(read_mrclam(dir_.string(), 7), parse_error);
  EXPECT_THROW(read_mrclam(dir_.string(), 1, {.max_step = 0.0}), invalid_input_error);
}

TEST_F(MrclamFiles, ImplausibleTimeSpansAndRunsWithoutMeasurementsAreRefusedBeforeAnyStepIsMade) {
  // Issue 36: odometry and Vicon rows 1e7 s after the rest made the step splitter run for 110 s at
  // 16.6 GB and exit 0; measurements all outside the run gave a table of zeros.
  const auto message = [&](const MrclamOptions& options) {
    try {
      read_mrclam(dir_.string(), 1, options);
    } catch (const parse_error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  write("Robot1_Odometry.dat", "# t v w\n100.0 1.0 0.0\n100.5 1.0 0.0\n101.0 0.5 0.2\n1e7 0.0 0.0\n");
  EXPECT_NE(message({}).find("Robot1_Odometry.dat:5: 9999899.000000 s after the previous row, more than 60.000000 s "
                             "(MrclamOptions::max_gap)"),
            std::string::npos)
      << message({});
  write("Robot1_Odometry.dat", "# t v w\n100.0 1.0 0.0\n103.0 0.0 0.0\n");
  write("Robot1_Groundtruth.dat", "# t x y h\n99.0 0.0 0.0 3.0\n101.0 2.0 0.0 -3.0\n5e6 5.0 0.0 -3.0\n");
  EXPECT_NE(message({}).find("Robot1_Groundtruth.dat:4:"), std::string::npos) << message({});
  rusage usage{};
  ::getrusage(RUSAGE_SELF, &usage);
  EXPECT_LT(usage.ru_maxrss, 200 * 1024) << "peak RSS in kB";

  // Within the gaps, more steps than the limit: refused by counting, before they are made.
  write("Robot1_Groundtruth.dat", "# t x y h\n99.0 0.0 0.0 3.0\n101.0 2.0 0.0 -3.0\n104.0 5.0 0.0 -3.0\n");
  EXPECT_NE(message({.max_step = 0.5, .max_steps = 5}).find("would be 7 steps, more than 5 (MrclamOptions::max_steps)"),
            std::string::npos)
      << message({.max_step = 0.5, .max_steps = 5});
  EXPECT_EQ(message({.max_step = 0.5, .max_steps = 7}), "no error");

  write("Robot1_Measurement.dat", "# t barcode r b\n99.5 63 1.0 0.0\n200.0 81 1.0 0.0\n");
  EXPECT_NE(message({}).find("no landmark measurement inside the odometry and Vicon time span (2 outside it"),
            std::string::npos)
      << message({});
}

/// Every measurement row of the real files ends up used or in exactly one drop count.
TEST(MrclamDataset6, EveryMeasurementIsUsedOrCountedAndStepsCoverTheRun) {
  const std::string dir = test::shared_data("mrclam/MRCLAM_Dataset6");
  SEXTANT_REQUIRE_DATA(dir);
  for (int robot = 1; robot <= 5; ++robot) {
    const auto run = read_mrclam(dir, robot);
    std::size_t rows = 0;
    std::ifstream in(dir + "/Robot" + std::to_string(robot) + "_Measurement.dat");
    for (std::string line; std::getline(in, line);) rows += !line.empty() && line[0] != '#';
    const auto& c = run.counts;
    EXPECT_EQ(c.measurements + c.robot_sightings + c.unknown_barcodes + c.outside_run + c.repeated_in_step, rows);
    EXPECT_GT(c.measurements, 1000u) << "robot " << robot;
    double covered = 0.0;
    std::size_t observed = 0;
    for (const auto& step : run.steps) {
      EXPECT_GT(step.dt, 0.0);
      EXPECT_LE(step.dt, 0.25 + 1e-9);
      covered += step.dt;
      for (const auto& o : step.observations) EXPECT_TRUE(run.true_landmarks.contains(o.landmark_id));
      observed += step.observations.size();
    }
    EXPECT_EQ(observed, c.measurements);
    EXPECT_NEAR(covered, run.step_times.back(), 1e-6);
    EXPECT_EQ(run.true_poses.size(), run.steps.size() + 1);
    EXPECT_EQ(run.true_landmarks.size(), 15u);
  }
}

}  // namespace
}  // namespace sextant::io
