// sextant-globe-stereo (and sextant-run handing over to it) as a user meets it: the rendered globe
// through the front-end and every back-end, its sequence written with --save-images and read back
// with --dataset stereo:<dir> to the same observations, and a bad directory stopping with one line.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "support/run_program.hpp"

namespace {

namespace fs = std::filesystem;
using sextant::test::run_program;

class GlobeStereoRunner : public ::testing::Test {
 protected:
  fs::path dir = fs::temp_directory_path() / ("sextant_globe_stereo_" + std::to_string(::getpid()) + "_" +
                                              ::testing::UnitTest::GetInstance()->current_test_info()->name());
  void SetUp() override { fs::create_directories(dir); }
  void TearDown() override { fs::remove_all(dir); }

  fs::path short_run_config() const {
    const auto ini = dir / "short.ini";
    std::ofstream(ini) << "[globe]\nsteps = 8\ngraph_updates = 1\nseif_active = 0\n[fastslam]\nparticles = 5\n";
    return ini;
  }
};

std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST_F(GlobeStereoRunner, SavedImagesReadBackGiveTheSameObservations) {
  const auto images = dir / "sequence";
  const auto rendered = run_program(std::string(SEXTANT_GLOBE_STEREO_EXE) + " -d globe-stereo -c " +
                                        short_run_config().string() + " --save-images " + images.string() + " -o " +
                                        (dir / "a").string(),
                                    dir);
  ASSERT_EQ(rendered.exit_code, 0) << rendered.err;
  for (const char* row : {"EKF-SLAM", "SEIF-SLAM, all active", "GraphSLAM", "FastSLAM 1.0", "FastSLAM 2.0",
                          "association precision", "frames/s"})
    EXPECT_NE(rendered.out.find(row), std::string::npos) << row << " missing from:\n" << rendered.out;
  EXPECT_TRUE(fs::exists(images / "left" / "000007.png") && fs::exists(images / "right" / "000007.png"));
  EXPECT_TRUE(fs::exists(images / "calib.yaml"));

  const auto replayed = run_program(std::string(SEXTANT_RUN_EXE) + " -d stereo:" + images.string() + " -c " +
                                        short_run_config().string() + " -o " + (dir / "b").string(),
                                    dir);
  ASSERT_EQ(replayed.exit_code, 0) << replayed.err;
  const std::string in_memory = slurp(dir / "a" / "globe-stereo" / "observations.csv");
  EXPECT_GT(std::count(in_memory.begin(), in_memory.end(), '\n'), 8 * 50);  // header + rows: several per frame
  EXPECT_EQ(slurp(dir / "b" / "stereo" / "observations.csv"), in_memory);
  EXPECT_TRUE(fs::exists(dir / "b" / "stereo" / "ekf_trajectory.tum"));
}

/// `[globe] tracker = eseif` tracks with the relocalizing SEIF (its conditional gate by default); an
/// eseif tracker without an active count is refused with a line naming the key.
TEST_F(GlobeStereoRunner, AnEseifTrackerTracksAndOneWithoutAnActiveCountIsRefused) {
  const auto ini = dir / "eseif.ini";
  std::ofstream(ini) << "[globe]\nsteps = 8\ntracker = eseif\neseif_active = 150\n";
  const auto r = run_program(std::string(SEXTANT_GLOBE_STEREO_EXE) + " -d globe-stereo -b eseif -c " + ini.string(), dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* text : {"ESEIF back-end", "association precision", "ESEIF-SLAM, 150 active"})
    EXPECT_NE(r.out.find(text), std::string::npos) << text << " missing from:\n" << r.out;
  const std::string start = "The start: the prior's position is";  // once: the reference run shares the start
  const auto first_start = r.out.find(start);
  ASSERT_NE(first_start, std::string::npos) << r.out;
  EXPECT_EQ(r.out.find(start, first_start + 1), std::string::npos) << r.out;

  const auto none = dir / "none.ini";
  std::ofstream(none) << "[globe]\nsteps = 8\ntracker = eseif\neseif_active = none\n";
  const auto refused = run_program(std::string(SEXTANT_GLOBE_STEREO_EXE) + " -d globe-stereo -b ekf -c " + none.string(), dir);
  EXPECT_NE(refused.exit_code, 0);
  EXPECT_NE(refused.err.find("eseif_active"), std::string::npos) << refused.err;
}

/// `[globe] texture_seed` reaches the renderer: the same orbit's first pair comes out another pattern,
/// and the header names the seed.
TEST_F(GlobeStereoRunner, AnotherTextureSeedRendersAnotherPattern) {
  auto first_left = [&](const std::string& texture_seed) {
    const auto ini = dir / ("texture" + texture_seed + ".ini");
    std::ofstream(ini) << "[globe]\nsteps = 1\ntexture_seed = " << texture_seed << "\n";
    const auto images = dir / ("images" + texture_seed);
    const auto r = run_program(std::string(SEXTANT_GLOBE_STEREO_EXE) + " -d globe-stereo -b ekf -c " + ini.string() +
                                   " --save-images " + images.string(),
                               dir);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find("texture seed " + texture_seed), std::string::npos) << r.out;
    return slurp(images / "left" / "000000.png");
  };
  const std::string one = first_left("1"), two = first_left("2");
  EXPECT_FALSE(one.empty());
  EXPECT_FALSE(two.empty());
  EXPECT_TRUE(one != two) << "texture seeds 1 and 2 rendered the same first left image";
}

TEST_F(GlobeStereoRunner, ABadSequenceStopsWithOneLineNamingTheFile) {
  fs::create_directories(dir / "empty" / "left");
  fs::create_directories(dir / "empty" / "right");
  const auto r = run_program(std::string(SEXTANT_GLOBE_STEREO_EXE) + " -d stereo:" + (dir / "empty").string(), dir);
  EXPECT_NE(r.exit_code, 0);
  EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << "not one line: " << r.err;
  EXPECT_NE(r.err.find("calib.yaml"), std::string::npos) << r.err;

  const auto mixed = run_program(std::string(SEXTANT_RUN_EXE) + " -d globe-stereo -d ship", dir);
  EXPECT_NE(mixed.exit_code, 0);
  EXPECT_NE(mixed.err.find("sextant-globe-stereo"), std::string::npos) << mixed.err;
}

}  // namespace
