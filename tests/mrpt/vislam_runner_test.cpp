// sextant-vislam (and sextant-run handing over to it) as a user meets it: the simulated stereo car
// and the KITTI-derived .npz files run every back-end, write trajectories, maps and scenes, and the
// visual-inertial EKF beats dead reckoning on 0027_noisy.npz as issue 13 asks.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <mrpt/opengl/COpenGLScene.h>
#include <sstream>
#include <string>
#include <vector>

#include "sextant/mrpt/scene.hpp"
#include "support/run_program.hpp"
#include "support/shared_data.hpp"

namespace {

namespace fs = std::filesystem;
using sextant::test::run_program;

class VislamRunner : public ::testing::Test {
 protected:
  fs::path dir = fs::temp_directory_path() / ("sextant_vislam_" + std::to_string(::getpid()) + "_" +
                                              ::testing::UnitTest::GetInstance()->current_test_info()->name());
  void SetUp() override { fs::create_directories(dir); }
  void TearDown() override { fs::remove_all(dir); }

  fs::path short_run_config() const {
    const auto ini = dir / "short.ini";
    std::ofstream(ini) << "[vislam]\nsteps = 80\n[fastslam]\nparticles = 10\n";
    return ini;
  }
};

/// The table's rows by label: the columns after the label (length ... ms/frame) as text.
std::map<std::string, std::vector<std::string>> table_rows(const std::string& out) {
  std::map<std::string, std::vector<std::string>> rows;
  std::stringstream lines(out);
  for (std::string line; std::getline(lines, line);) {
    std::stringstream fields(line);
    std::vector<std::string> tokens;
    for (std::string t; fields >> t;) tokens.push_back(t);
    constexpr std::size_t columns = 10;  // length, in state, mapped, corrected, gated, unusable, RMSE, vs DR, ANEES, ms
    if (tokens.size() <= columns) continue;
    auto is_number = [](const std::string& t) { return t.find_first_not_of("0123456789.") == std::string::npos && t.back() != '.'; };
    if (!std::all_of(tokens.end() - columns, tokens.end() - 4, is_number) || !is_number(tokens.back())) continue;
    const auto at = line.find(tokens[tokens.size() - columns]);
    std::string label = line.substr(0, at);
    label.erase(label.find_last_not_of(' ') + 1);
    rows[label].assign(tokens.end() - columns, tokens.end());
  }
  return rows;
}

double rmse_of(const std::vector<std::string>& row) { return std::stod(row.at(6)); }

std::size_t count_lines(const fs::path& path) {
  std::ifstream in(path);
  std::size_t n = 0;
  for (std::string line; std::getline(in, line);) n += !line.empty() && line[0] != '#';
  return n;
}

TEST_F(VislamRunner, StereoViRunsEveryBackEndAndWritesTrajectoriesMapsAndScenes) {
  const auto out = dir / "out";
  const auto r = run_program(std::string(SEXTANT_VISLAM_EXE) + " -d stereo-vi -c " + short_run_config().string() +
                                 " -o " + out.string(),
                             dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto rows = table_rows(r.out);
  for (const char* label : {"dead reckoning (IMU only)", "EKF-SLAM", "EKF-SLAM, first-estimate Jacobians",
                            "SEIF-SLAM, 8 active", "FastSLAM 1.0, 10 particles", "FastSLAM 2.0, 10 particles"})
    EXPECT_TRUE(rows.contains(label)) << label << " not a row of:\n" << r.out;
  EXPECT_NE(r.out.find("GraphSLAM, LM"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("GraphSLAM from EKF, LM"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("nan"), std::string::npos) << "a score not computed must print as -:\n" << r.out;
  for (const auto& [label, row] : rows) {
    EXPECT_GT(rmse_of(row), 0.0) << label;  // scored against the simulator's truth
    if (label != "dead reckoning (IMU only)") {
      EXPECT_GT(std::stoul(row.at(2)), 0u) << label << " mapped nothing";
    }
  }
  const auto data = out / "stereo-vi";
  EXPECT_EQ(count_lines(data / "reference.tum"), 80u);
  for (const char* key : {"dead_reckoning", "ekf", "ekf_fej", "seif", "graph", "graph_from_ekf", "fastslam1", "fastslam2"})
    EXPECT_EQ(count_lines(data / (std::string(key) + "_trajectory.tum")), 80u) << key;
  std::ifstream map(data / "ekf_map.csv");
  std::string header;
  std::getline(map, header);
  EXPECT_EQ(header, "id,x,y,z");
  EXPECT_GT(count_lines(data / "ekf_map.csv"), 10u);
  mrpt::opengl::COpenGLScene scene;
  ASSERT_TRUE(scene.loadFromFile((data / "ekf_fej.3Dscene").string()));
  EXPECT_TRUE(scene.getByName(sextant::mrpt_io::scene_names::true_landmarks));
}

TEST_F(VislamRunner, SextantRunHandsStereoViAndNpzOverAndRefusesMixtures) {
  const auto r = run_program(std::string(SEXTANT_RUN_EXE) + " -d stereo-vi -b ekf -c " + short_run_config().string(), dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(table_rows(r.out).contains("EKF-SLAM, first-estimate Jacobians")) << r.out;

  const auto mixed = run_program(std::string(SEXTANT_RUN_EXE) + " -d stereo-vi -d ship", dir);
  EXPECT_NE(mixed.exit_code, 0);
  EXPECT_EQ(mixed.err.find('\n'), mixed.err.size() - 1) << "not one line: " << mixed.err;
  EXPECT_NE(mixed.err.find("runs alone"), std::string::npos) << mixed.err;
  EXPECT_NE(mixed.err.find("sextant-vislam"), std::string::npos) << mixed.err;

  const auto other = run_program(std::string(SEXTANT_VISLAM_EXE) + " -d ship", dir);
  EXPECT_NE(other.exit_code, 0);
  EXPECT_NE(other.err.find("sextant-vislam runs stereo-vi and .npz files"), std::string::npos) << other.err;
}

TEST_F(VislamRunner, EkfOn0027NoisyIsTwiceAsCloseToTheCleanReferenceAsDeadReckoning) {
  const auto noisy = sextant::test::shared_data("ece276a/0027_noisy.npz");
  SEXTANT_REQUIRE_DATA(noisy);
  SEXTANT_REQUIRE_DATA(sextant::test::shared_data("ece276a/0027_clean.npz"));
  const auto r = run_program(std::string(SEXTANT_VISLAM_EXE) + " -b ekf -d " + noisy, dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto rows = table_rows(r.out);
  ASSERT_TRUE(rows.contains("dead reckoning (IMU only)") && rows.contains("EKF-SLAM")) << r.out;
  // Issue 13's goal: the VI-SLAM trajectory at least 2x closer (position RMSE) to the dead
  // reckoning of 0027_clean.npz than the noisy file's own dead reckoning.
  EXPECT_GE(rmse_of(rows.at("dead reckoning (IMU only)")), 2.0 * rmse_of(rows.at("EKF-SLAM"))) << r.out;
}

TEST_F(VislamRunner, ACleanTwinWithOtherFramesIsNamedNotSilentlyDropped) {
  // Issue 36: a NAME_clean.npz beside NAME_noisy.npz with fewer frames was ignored without a word.
  const auto kitti = sextant::test::shared_data("ece276a/03.npz");
  const auto clean = sextant::test::shared_data("ece276a/0027_clean.npz");
  SEXTANT_REQUIRE_DATA(kitti);
  SEXTANT_REQUIRE_DATA(clean);
  fs::copy_file(kitti, dir / "pair_noisy.npz");
  fs::copy_file(clean, dir / "pair_clean.npz");
  const auto r = run_program(std::string(SEXTANT_VISLAM_EXE) + " -b ekf -d " + (dir / "pair_noisy.npz").string(), dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("note: pair_clean.npz has 1106 frames, pair_noisy.npz 1010: no reference"), std::string::npos)
      << r.out;
}

TEST_F(VislamRunner, ACleanTwinWithShiftedTimeStampsIsUsedWithAWarning) {
  // Issue 36: a NAME_clean.npz whose time stamps are 1000 s off was used as the reference without a word.
  const auto noisy = sextant::test::shared_data("ece276a/0027_noisy.npz");
  const auto clean = sextant::test::shared_data("ece276a/0027_clean.npz");
  SEXTANT_REQUIRE_DATA(noisy);
  SEXTANT_REQUIRE_DATA(clean);
  fs::copy_file(noisy, dir / "shifted_noisy.npz");
  // numpy comes with python3-matplotlib (cmake/install_deps.sh), as for the fuzzers' seeds.
  const auto shift = run_program("/usr/bin/python3 -c \"import numpy as np; d = dict(np.load('" + clean +
                                     "')); d['time_stamps'] = d['time_stamps'] + 1000.0; np.savez('" +
                                     (dir / "shifted_clean.npz").string() + "', **d)\"",
                                 dir);
  if (shift.exit_code != 0) GTEST_SKIP() << "numpy could not write the shifted copy: " << shift.err;
  const auto r = run_program(std::string(SEXTANT_VISLAM_EXE) + " -b ekf -d " + (dir / "shifted_noisy.npz").string(), dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("warning: the time stamps of shifted_clean.npz differ from those of shifted_noisy.npz by up to 1000 s"),
            std::string::npos)
      << r.out;
}

}  // namespace
