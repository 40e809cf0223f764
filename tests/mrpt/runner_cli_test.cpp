// sextant-run as a user meets it: a run writes the promised files, its .3Dscene loads back in MRPT,
// and bad input (missing, truncated or malformed rawlog, unknown config key or value) ends with a
// non-zero exit and one line naming the file and the problem.
#include <gtest/gtest.h>

#include <sextant/io/pose_graph_file.hpp>
#include <Eigen/Geometry>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <mrpt/opengl/CEllipsoid2D.h>
#include <mrpt/opengl/CEllipsoid3D.h>
#include <mrpt/opengl/COpenGLScene.h>
#include <mrpt/opengl/CPointCloud.h>
#include <mrpt/opengl/CSetOfLines.h>
#include <mrpt/opengl/CSetOfObjects.h>
#include <sstream>
#include <string>

#include "mrpt/mrpt_demo_data.hpp"
#include "sextant/mrpt/scene.hpp"
#include "support/run_program.hpp"
#include "support/shared_data.hpp"

namespace {

namespace fs = std::filesystem;
using sextant::testing::mrpt_demo;

using Result = sextant::test::ProgramResult;
using sextant::test::run_program;

Result run_runner(const std::string& arguments, const fs::path& dir) {
  return run_program(std::string(SEXTANT_RUN_EXE) + " " + arguments, dir);
}

/// The whole of a file (summary.json, the docs); empty when it cannot be read.
std::string text_of(const fs::path& path) {
  std::ifstream file(path);
  std::stringstream text;
  text << file.rdbuf();
  return text.str();
}

class RunnerCli : public ::testing::Test {
 protected:
  fs::path dir = fs::temp_directory_path() / ("sextant_run_cli_" + std::to_string(::getpid()) + "_" +
                                              ::testing::UnitTest::GetInstance()->current_test_info()->name());
  void SetUp() override { fs::create_directories(dir); }
  void TearDown() override { fs::remove_all(dir); }

  /// Expects failure with exactly one line on stderr that contains every fragment.
  void expect_one_line_error(const std::string& arguments, const std::vector<std::string>& fragments) {
    const auto r = run_runner(arguments, dir);
    EXPECT_NE(r.exit_code, 0) << arguments;
    ASSERT_FALSE(r.err.empty()) << arguments;
    EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << "not one line: " << r.err;
    for (const auto& f : fragments) EXPECT_NE(r.err.find(f), std::string::npos) << "'" << f << "' not in: " << r.err;
  }

  /// A copy of a demo rawlog and its ground truth under a new name in `dir`.
  fs::path copy_demo(const std::string& demo, const std::string& name) {
    const fs::path source = mrpt_demo(demo);
    const auto stem = source.parent_path() / source.stem();
    fs::copy_file(source, dir / (name + ".rawlog"));
    fs::copy_file(stem.string() + "_ground_truth.txt", dir / (name + "_ground_truth.txt"));
    fs::copy_file(stem.string() + "_ground_truth_robot_path.txt", dir / (name + "_ground_truth_robot_path.txt"));
    return dir / (name + ".rawlog");
  }
};

TEST_F(RunnerCli, PlanarRunWritesTableCsvTumJsonAndALoadableScene) {
  SEXTANT_REQUIRE_MRPT_DEMO("kf-slam_demo.rawlog");
  const auto out = dir / "out";
  const auto r = run_runner("--dataset " + mrpt_demo("kf-slam_demo.rawlog") + " --backend ekf,fastslam2 --out " + out.string(), dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("EKF-SLAM"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("FastSLAM 2.0"), std::string::npos) << r.out;
  for (const char* file : {"ekf_steps.csv", "ekf_map.csv", "ekf_trajectory.tum", "ground_truth.tum", "ekf.3Dscene",
                           "fastslam2.3Dscene"})
    EXPECT_TRUE(fs::exists(out / "kf-slam_demo" / file)) << file;
  EXPECT_TRUE(fs::exists(out / "summary.json"));

  mrpt::opengl::COpenGLScene scene;
  ASSERT_TRUE(scene.loadFromFile((out / "kf-slam_demo" / "ekf.3Dscene").string()));
  const auto path = std::dynamic_pointer_cast<mrpt::opengl::CSetOfLines>(scene.getByName(sextant::mrpt_io::scene_names::estimated_path));
  ASSERT_TRUE(path);
  EXPECT_EQ(path->size(), 248u);  // 249 poses
  ASSERT_TRUE(scene.getByName(sextant::mrpt_io::scene_names::true_path));
  const auto landmarks = std::dynamic_pointer_cast<mrpt::opengl::CSetOfObjects>(scene.getByName(sextant::mrpt_io::scene_names::landmarks));
  ASSERT_TRUE(landmarks);
  std::size_t ellipses = 0;
  for (const auto& object : *landmarks) ellipses += std::dynamic_pointer_cast<mrpt::opengl::CEllipsoid2D>(object) != nullptr;
  EXPECT_EQ(ellipses, 70u);
  EXPECT_TRUE(landmarks->getByName("landmark 7"));

  ASSERT_TRUE(scene.loadFromFile((out / "kf-slam_demo" / "fastslam2.3Dscene").string()));
  const auto particles = std::dynamic_pointer_cast<mrpt::opengl::CPointCloud>(scene.getByName(sextant::mrpt_io::scene_names::particles));
  ASSERT_TRUE(particles);
  EXPECT_EQ(particles->size(), 100u);  // the default [fastslam] particles
}

TEST_F(RunnerCli, GlobeRunsEveryBackEndThroughThePoolAndWritesBookkeepingAndScenes) {
  // A short globe with a small pool, so that eviction happens: one row per back-end configuration.
  const auto ini = dir / "globe.ini";
  std::ofstream(ini) << "[globe]\nsteps = 60\npoints = 800\nfeatures_per_frame = 40\nmax_landmarks = 45\n"
                        "max_new_per_step = 10\nseif_active = 20 0\neseif_active = 20\ngraph_updates = 2\n[fastslam]\nparticles = 10\n";
  const auto out = dir / "out";
  const auto r = run_runner("--dataset globe --config " + ini.string() + " --out " + out.string(), dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* label : {"EKF-SLAM", "SEIF-SLAM, 20 active", "ESEIF-SLAM, 20 active", "SEIF-SLAM, all active", "GraphSLAM, windows 50 x 5",
                            "FastSLAM 1.0", "FastSLAM 2.0", "after each global update", "ms per frame"})
    EXPECT_NE(r.out.find(label), std::string::npos) << label << " not in:\n" << r.out;
  EXPECT_EQ(r.out.find("nan"), std::string::npos) << "a score not computed must print as -:\n" << r.out;
  std::ifstream csv(out / "globe" / "ekf_steps.csv");
  std::string line;
  std::getline(csv, line);
  EXPECT_EQ(line, "step,position_error,rotation_error,in_pool,added,evicted,refused,seconds");
  double evicted = 0.0, most_in_pool = 0.0;
  int rows = 0;
  while (std::getline(csv, line)) {
    std::vector<double> v;
    std::stringstream fields(line);
    for (std::string f; std::getline(fields, f, ',');) v.push_back(std::stod(f));
    ASSERT_EQ(v.size(), 8u);
    EXPECT_LE(v[3], 45.0) << "pool over capacity at step " << v[0];
    EXPECT_GT(v[7], 0.0) << "no time recorded for step " << v[0];
    EXPECT_LE(v[4], 10.0) << "more than max_new added at step " << v[0];
    evicted += v[5];
    most_in_pool = std::max(most_in_pool, v[3]);
    ++rows;
  }
  EXPECT_EQ(rows, 60);
  EXPECT_GT(evicted, 0.0);
  EXPECT_EQ(most_in_pool, 45.0) << "the pool fills to capacity";
  mrpt::opengl::COpenGLScene scene;
  ASSERT_TRUE(scene.loadFromFile((out / "globe" / "seifall.3Dscene").string()));
  EXPECT_TRUE(scene.getByName(sextant::mrpt_io::scene_names::true_landmarks));
  EXPECT_TRUE(fs::exists(out / "globe" / "graph_trajectory.tum"));
  // GraphSLAM's NEES from its smoothed marginals, at the filters' sampled steps (every 10th).
  std::ifstream nees(out / "globe" / "graph_nees.csv");
  std::getline(nees, line);
  EXPECT_EQ(line, "step,position_nees,rotation_nees");
  std::vector<double> steps;
  while (std::getline(nees, line)) {
    std::vector<double> v;
    std::stringstream fields(line);
    for (std::string f; std::getline(fields, f, ',');) v.push_back(std::stod(f));
    ASSERT_EQ(v.size(), 3u);
    EXPECT_TRUE(std::isfinite(v[1]) && v[1] >= 0.0 && std::isfinite(v[2]) && v[2] >= 0.0) << line;
    steps.push_back(v[0]);
  }
  EXPECT_EQ(steps, (std::vector<double>{10, 20, 30, 40, 50, 60}));
  EXPECT_NE(r.out.find("GraphSLAM NEES: smoothed marginals"), std::string::npos) << r.out;
  // The start's draw, which every step's NEES carries: under the isotropic 1 mm prior (the globe's
  // default) its NEES is (distance / 1 mm)^2, to the printed digits.
  const auto start = r.out.find("The start: the prior's position is ");
  ASSERT_NE(start, std::string::npos) << r.out;
  double mm = -1.0, start_nees = -1.0;
  ASSERT_EQ(std::sscanf(r.out.c_str() + start, "The start: the prior's position is %lf mm off the true first pose, NEES %lf", &mm,
                        &start_nees), 2) << r.out.substr(start, 200);
  EXPECT_GT(mm, 0.0);
  EXPECT_NEAR(start_nees, mm * mm, 0.01 * mm + 0.006) << "printed to two decimals each";
}

TEST_F(RunnerCli, GlobeRunsAloneInItsOwnProgram) {
  // sextant-run hands --dataset globe over to sextant-globe; mixing it with other data sets, or giving
  // sextant-globe another data set, is refused with one line.
  expect_one_line_error("-d globe -d ship", {"--dataset globe: runs alone", "sextant-globe"});
  const std::string globe = (fs::path(SEXTANT_RUN_EXE).parent_path() / "sextant-globe").string();
  const auto r = run_program(globe + " -d ship", dir);
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("sextant-globe runs only the globe"), std::string::npos) << r.err;
}

TEST_F(RunnerCli, MrclamAndIsamRunInTheirOwnPrograms) {
  // The main job does not compile them: sextant-run hands mrclam:... to sextant-run-mrclam and iSAM
  // text files to sextant-run-isam, and refuses a mixture with one line naming the program; each
  // program refuses the other data sets.
  expect_one_line_error("-d ship -d mrclam:/nowhere:1", {"--dataset mrclam", "runs alone", "sextant-run-mrclam"});
  expect_one_line_error("-d ship -d loop.txt", {"runs alone", "sextant-run-isam"});
  const auto bin = fs::path(SEXTANT_RUN_EXE).parent_path();
  for (const char* program : {"sextant-run-mrclam", "sextant-run-isam"}) {
    const auto r = run_program((bin / program).string() + " -d ship", dir);
    EXPECT_NE(r.exit_code, 0);
    EXPECT_NE(r.err.find(std::string(program) + " runs"), std::string::npos) << r.err;
  }
}

/// An MRCLAM run prints, below each robot's table, the EKF given the surveyed map: the same filter
/// with every landmark known before it is seen, which has more to go on than EKF-SLAM and so must not
/// end further from Vicon after alignment (the peer is the EKF row of the same run).
TEST_F(RunnerCli, MrclamPrintsTheFilterGivenTheSurveyedMap) {
  const std::string data = sextant::test::shared_data("mrclam/MRCLAM_Dataset6");
  SEXTANT_REQUIRE_DATA(data);
  const auto r = run_runner("-d mrclam:" + data + ":1 -b ekf", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto given = r.out.find("the EKF given the surveyed map");
  ASSERT_NE(given, std::string::npos) << r.out;
  double given_rmse = 0.0, given_aligned = 0.0, ekf_rmse = 0.0, ekf_aligned = 0.0;
  ASSERT_EQ(std::sscanf(r.out.c_str() + r.out.find("position RMSE", given), "position RMSE %lf m (aligned %lf)", &given_rmse,
                        &given_aligned), 2) << r.out;
  ASSERT_EQ(std::sscanf(r.out.c_str() + r.out.find(", ekf ", given), ", ekf %lf (%lf)", &ekf_rmse, &ekf_aligned), 2) << r.out;
  EXPECT_GT(given_aligned, 0.0);
  EXPECT_LT(given_aligned, ekf_aligned);
  EXPECT_LT(given_rmse, ekf_rmse);
}

/// On the iSAM text files the filters run in the world chart by default ([isam]
/// filters_in_world_frame, docs/results/victoria_park.md). cityTrees10000 has a noise-free ground
/// truth: the EKF row there is nearer the truth and less overconfident than the same filter in the
/// additive chart (`false`, the peer in the same test), which gains heading information the data
/// cannot give.
TEST_F(RunnerCli, IsamFiltersRunInTheWorldChartByDefault) {
  const std::string data = sextant::test::shared_data("city_trees/cityTrees10000.txt");
  SEXTANT_REQUIRE_DATA(data);
  std::ofstream(dir / "additive.ini") << "[isam]\nfilters_in_world_frame = false\n";
  struct Row {
    double pose_mae = 0.0, anees = 0.0;
  };
  auto ekf_row = [&](const std::string& arguments, bool world) {
    const auto r = run_runner("-d " + data + " -b ekf " + arguments, dir);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(r.out.find("perturb the pose in the world frame") != std::string::npos, world) << r.out;
    Row row;
    double aligned = 0.0, map = 0.0, map_aligned = 0.0, inside = 0.0, map_inside = 0.0;
    const auto at = r.out.find("EKF-SLAM");
    EXPECT_NE(at, std::string::npos) << r.out;
    if (at == std::string::npos) return row;
    EXPECT_EQ(std::sscanf(r.out.c_str() + at, "EKF-SLAM %lf %lf %lf %lf %lf%% %lf%% %lf", &row.pose_mae, &aligned, &map,
                          &map_aligned, &inside, &map_inside, &row.anees), 7)
        << r.out;
    return row;
  };
  const Row world = ekf_row("", true), additive = ekf_row("-c " + (dir / "additive.ini").string(), false);
  EXPECT_LT(world.pose_mae, additive.pose_mae);
  EXPECT_LT(world.anees, additive.anees);
}

TEST_F(RunnerCli, SpatialRunDrawsLandmarkEllipsoids) {
  SEXTANT_REQUIRE_MRPT_DEMO("kf-slam_6D_demo_noncentered.rawlog");
  const auto out = dir / "out";
  const auto r = run_runner("-d " + mrpt_demo("kf-slam_6D_demo_noncentered.rawlog") + " -b ekf -o " + out.string(), dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  mrpt::opengl::COpenGLScene scene;
  ASSERT_TRUE(scene.loadFromFile((out / "kf-slam_6D_demo_noncentered" / "ekf.3Dscene").string()));
  const auto landmarks = std::dynamic_pointer_cast<mrpt::opengl::CSetOfObjects>(scene.getByName(sextant::mrpt_io::scene_names::landmarks));
  ASSERT_TRUE(landmarks);
  std::size_t ellipsoids = 0;
  for (const auto& object : *landmarks) ellipsoids += std::dynamic_pointer_cast<mrpt::opengl::CEllipsoid3D>(object) != nullptr;
  EXPECT_GT(ellipsoids, 40u);
}

TEST_F(RunnerCli, PlotsAreWritten) {
  SEXTANT_REQUIRE_MRPT_DEMO("kf-slam_demo.rawlog");
  const auto out = dir / "out";
  const auto r = run_runner("-d " + mrpt_demo("kf-slam_demo.rawlog") + " -b ekf --plots -o " + out.string(), dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_GT(fs::file_size(out / "kf-slam_demo" / "ekf_map.png"), 10000u);
  EXPECT_GT(fs::file_size(out / "kf-slam_demo" / "ekf_errors.png"), 10000u);
}

TEST_F(RunnerCli, BadRawlogsEndWithOneLineNamingFileAndProblem) {
  SEXTANT_REQUIRE_MRPT_DEMO("kf-slam_demo.rawlog");
  const auto missing = (dir / "missing.rawlog").string();
  expect_one_line_error("-d " + missing, {missing, "cannot open file"});

  const auto truncated = copy_demo("kf-slam_demo.rawlog", "truncated");
  fs::resize_file(truncated, fs::file_size(truncated) / 2);
  expect_one_line_error("-d " + truncated.string(), {truncated.string(), "truncated or malformed"});

  const auto garbage = dir / "garbage.rawlog";
  std::ofstream(garbage) << "definitely not an MRPT rawlog\n";
  expect_one_line_error("-d " + garbage.string(), {garbage.string(), "truncated or malformed"});

  const auto no_truth = dir / "no_truth.rawlog";
  fs::copy_file(mrpt_demo("kf-slam_demo.rawlog"), no_truth);
  expect_one_line_error("-d " + no_truth.string(), {no_truth.string(), "no ground truth"});
}

TEST_F(RunnerCli, BadConfigEndsWithOneLineNamingFileKeyAndProblem) {
  const auto ini = (dir / "bad.ini").string();
  std::ofstream(ini) << "[ekf]\nbatch_update = true\ngate_probabilty = 0.99\n";
  expect_one_line_error("-d ship -c " + ini, {ini, "[ekf] gate_probabilty", "unknown key"});

  std::ofstream(ini) << "[seif]\nmax_active = lots\n";
  expect_one_line_error("-d ship -c " + ini, {ini, "[seif] max_active", "'lots' is not a finite number"});

  std::ofstream(ini) << "[nonsense]\nkey = 1\n";
  expect_one_line_error("-d ship -c " + ini, {ini, "[nonsense] key", "unknown key"});

  // Found by the fuzzer (tests/fuzz/runner_config_fuzz): MRPT's parser threw its own exception on an
  // unclosed "$env{X", which escaped as an uncaught exception.
  std::ofstream(ini) << "[ekf]\nbatch_update = $env{X\n";
  expect_one_line_error("-d ship -c " + ini, {ini, "not a readable ini file (Line 2: Expected closing"});

  // Found by the fuzzer: 5.5e81 was converted to long long (undefined behaviour), and values above
  // an int's range were truncated silently.
  std::ofstream(ini) << "[ship]\nruns = 5.5e81\n";
  expect_one_line_error("-d ship -c " + ini, {ini, "[ship] runs", "is not an integer in [1, 100000]"});

  const auto missing = (dir / "missing.ini").string();
  expect_one_line_error("-d ship -c " + missing, {missing, "cannot open config file"});

  expect_one_line_error("-d ship -b kalman", {"--backend", "unknown back-end 'kalman'"});
}

TEST_F(RunnerCli, ConfigFilesThatAreNotSettingsAreRefused) {
  // Issue 36: each of these ran silently with the defaults (or ended in std::bad_alloc naming no key).
  const auto ini = (dir / "odd.ini").string();
  auto refused = [&](const std::string& content, const std::vector<std::string>& fragments) {
    std::ofstream(ini, std::ios::binary | std::ios::trunc) << content;
    expect_one_line_error("-d ship -c " + ini, fragments);
  };
  refused("these are words\nand more words\n", {ini + ":1:", "neither [section] nor key = value", "'these are words'"});
  refused("max_active = 3\n[seif]\n", {ini + ":1:", "max_active: a key before any [section]"});
  refused("[ekf]\nbatch_update = true\n\nbatch_update = false\n", {ini + ":4:", "[ekf] batch_update: given twice (first at line 2)"});
  refused("[ekf\nbatch_update = true\n", {ini + ":1:", "a section header without ']'"});
  refused("[rawlog]\nstd_range = -1\n", {ini, "[rawlog] std_range", "must be >= 0"});
  refused("[rawlog]\nstd_yaw_deg = -2\n", {ini, "[rawlog] std_yaw_deg", "must be >= 0"});
  refused("[rawlog]\nstd_pitch_deg = -0.05\n", {ini, "[rawlog] std_pitch_deg", "must be >= 0"});
  refused("[fastslam]\nparticles = 2000000000\n", {ini, "[fastslam] particles", "is not an integer in [1, 1000000]"});
  refused("[ship]\nsteps = 2000000000\n", {ini, "[ship] steps", "is not an integer in [1, 10000000]"});
  refused("[globe]\nseif_active = 150 2000000000\n", {ini, "[globe] seif_active", "is not an integer in [0, 1000000]"});
  refused("[globe]\neseif_active = 0\n", {ini, "[globe] eseif_active", "is not an integer in [1, 1000000]"});

  // Random bytes: refused, and the message shows no raw byte.
  std::string bytes = "[ship]\nseed = 1\n";
  for (int i = 0; i < 64; ++i) bytes += static_cast<char>((i * 37 + 11) % 256);
  std::ofstream(ini, std::ios::binary | std::ios::trunc) << bytes;
  const auto r = run_runner("-d ship -c " + ini, dir);
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find(ini + ":3: not a text line"), std::string::npos) << r.err;
  for (std::size_t k = 0; k + 1 < r.err.size(); ++k)
    EXPECT_TRUE(r.err[k] >= 0x20 && r.err[k] < 0x7f) << "raw byte " << static_cast<int>(static_cast<unsigned char>(r.err[k]))
                                                    << " at " << k << " in: " << r.err;

  // A file the process cannot read is an error, never the defaults. Root reads any file: there the
  // permission cannot be taken away, and only the directory case is checked.
  expect_one_line_error("-d ship -c " + dir.string(), {dir.string(), "cannot open config file"});
  std::ofstream(ini, std::ios::trunc) << "[ship]\nruns = 1\n";
  fs::permissions(ini, fs::perms::none);
  if (::access(ini.c_str(), R_OK) != 0) expect_one_line_error("-d ship -c " + ini, {ini, "cannot read the config file"});
  fs::permissions(ini, fs::perms::owner_read | fs::perms::owner_write);
}

TEST_F(RunnerCli, ConfigReferenceInDocsIsThePrintedDefaults) {
  const auto r = run_runner("--print-config", dir);
  ASSERT_EQ(r.exit_code, 0);
  EXPECT_NE(text_of(SEXTANT_RUNNER_DOCS).find("```ini\n" + r.out + "```"), std::string::npos)
      << "docs/runner.md must hold the output of sextant-run --print-config in an ini block";
}

/// The README's results table is what the main job prints: its header line (the first line of the
/// README that starts with "back-end") equals the header sextant-run prints, and every back-end and
/// data set the README's table names is one the program prints.
TEST_F(RunnerCli, ReadmeTableIsTheProgramsOutput) {
  const auto r = run_runner("--dataset ship --runs 2", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  auto first_line_starting_with = [](std::istream& in, const std::string& prefix) {
    for (std::string line; std::getline(in, line);)
      if (line.rfind(prefix, 0) == 0) return line;
    return std::string();
  };
  std::istringstream printed(r.out);
  const std::string program_header = first_line_starting_with(printed, "back-end");
  ASSERT_FALSE(program_header.empty()) << r.out;
  std::ifstream readme(SEXTANT_README);
  ASSERT_TRUE(readme) << SEXTANT_README;
  std::stringstream all;
  all << readme.rdbuf();
  std::istringstream readme_lines(all.str());
  EXPECT_EQ(first_line_starting_with(readme_lines, "back-end"), program_header);
  for (const char* label : {"EKF-SLAM", "SEIF-SLAM, 8 active", "ESEIF-SLAM, 8 active", "GraphSLAM",
                            "FastSLAM 1.0, 100 particles", "FastSLAM 2.0, 100 particles"}) {
    EXPECT_NE(r.out.find(label), std::string::npos) << label << " not printed";
    EXPECT_NE(all.str().find(label), std::string::npos) << label << " not in the README";
  }
  for (const char* dataset : {"== ship", "== kf-slam_demo.rawlog", "== kf-slam_6D_demo.rawlog",
                                     "== kf-slam_6D_demo_noncentered.rawlog"})
    EXPECT_NE(all.str().find(dataset), std::string::npos) << dataset << " not in the README";
}

TEST_F(RunnerCli, ACollapsedCloudSaysSoInsteadOfPrintingItsNees) {
  // FastSLAM 1.0 on kf-slam_demo: its 1 cm measurements leave one or two of the 100 weighted draws
  // at almost every step, a covariance no NEES can be read from (5e5 before this column). FastSLAM
  // 2.0's particles report Gaussians: its ANEES stays a number.
  SEXTANT_REQUIRE_MRPT_DEMO("kf-slam_demo.rawlog");
  const auto out = dir / "collapsed";
  const auto r = run_runner("--dataset " + mrpt_demo("kf-slam_demo.rawlog") + " -b fastslam1,fastslam2 --out " + out.string(), dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::istringstream lines(r.out);
  std::string one, two, note;
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind("FastSLAM 1.0", 0) == 0) one = line;
    if (line.rfind("FastSLAM 2.0", 0) == 0) two = line;
    if (line.find("collapsed: at ") != std::string::npos) note = line;
  }
  EXPECT_NE(one.find(" collapsed "), std::string::npos) << r.out;
  EXPECT_EQ(two.find("collapsed"), std::string::npos) << r.out;
  EXPECT_NE(note.find("of the steps the pose rests on fewer than dof + 1 effective particles"), std::string::npos) << r.out;
  const std::string json = text_of(out / "summary.json");
  EXPECT_NE(json.find("\"pose_undersampled\": 0.9"), std::string::npos) << json;  // most steps
  EXPECT_NE(json.find("\"pose_undersampled\": 0,"), std::string::npos) << json;   // FastSLAM 2.0
  EXPECT_NE(note.find("; the ANEES over the other steps: "), std::string::npos) << r.out;
}

/// eseif is SEIF with relocalization beside seif, the thesis's, with a line saying how often it
/// relocalized; when [seif] sparsification makes seif relocalize as well, the two would be one
/// filter, and the table shows it once.
TEST_F(RunnerCli, EseifRunsBesideTheThesisSeifAndOnceWhenSeifRelocalizesToo) {
  const auto ini = (dir / "eseif.ini").string();
  std::ofstream(ini) << "[ship]\nruns = 1\nsteps = 60\n";
  const auto rows_labelled = [](const std::string& out, const std::string& label) {
    std::size_t count = 0;
    for (auto at = out.find("\n" + label + " "); at != std::string::npos; at = out.find("\n" + label + " ", at + 1)) ++count;
    return count;
  };
  const auto both = run_runner("-d ship -b seif,eseif -c " + ini, dir);
  ASSERT_EQ(both.exit_code, 0) << both.err;
  EXPECT_EQ(rows_labelled(both.out, "SEIF-SLAM, 8 active"), 1u) << both.out;
  EXPECT_EQ(rows_labelled(both.out, "ESEIF-SLAM, 8 active"), 1u) << both.out;
  EXPECT_NE(both.out.find("relocalized at "), std::string::npos) << both.out;  // ESEIF's line, below its row
  std::ofstream(ini, std::ios::app) << "[seif]\nsparsification = relocalization\n";
  const auto once = run_runner("-d ship -b seif,eseif -c " + ini, dir);
  ASSERT_EQ(once.exit_code, 0) << once.err;
  EXPECT_EQ(rows_labelled(once.out, "SEIF-SLAM, 8 active"), 0u) << once.out;
  EXPECT_EQ(rows_labelled(once.out, "ESEIF-SLAM, 8 active"), 1u) << once.out;
}

/// A GraphSLAM whose final optimization stopped at its iteration limit says so below its row (its
/// estimate is not the optimum); one that converged says nothing. One iteration from dead reckoning
/// cannot converge: its step is the whole correction, far above the step tolerance.
TEST_F(RunnerCli, GraphSlamStoppedBeforeConvergingSaysSo) {
  const auto ini = (dir / "graph.ini").string();
  std::ofstream(ini) << "[ship]\nruns = 2\nsteps = 60\n";
  const auto converged = run_runner("-d ship -b graph -c " + ini, dir);
  ASSERT_EQ(converged.exit_code, 0) << converged.err;
  EXPECT_EQ(converged.out.find("optimization stopped"), std::string::npos) << converged.out;
  std::ofstream(ini, std::ios::app) << "[graph]\nmax_iterations = 1\n";
  const auto stopped = run_runner("-d ship -b graph -c " + ini + " -o " + (dir / "stopped").string(), dir);
  ASSERT_EQ(stopped.exit_code, 0) << stopped.err;
  EXPECT_NE(stopped.out.find("optimization stopped at its limit of 1 iteration before converging in 2 of 2 runs; "
                             "[graph] max_iterations raises it"), std::string::npos) << stopped.out;
  const std::string json = text_of(dir / "stopped" / "summary.json");
  EXPECT_NE(json.find("\"optimization_unconverged_runs\": 2"), std::string::npos) << json;
}

/// A GraphSLAM whose Gauss-Newton rose says so below its row: by default it undid the rising step and
/// went on damped; with damp_after_rise off it kept its earlier, lower iterate; Levenberg-Marquardt,
/// which only accepts steps that lower the cost, prints neither. The data: an iSAM
/// file of a robot on a circle among 12 landmarks whose odometry headings carry a smooth error of up
/// to 5 rad, declared weak, so that dead reckoning (GraphSLAM's start, no windowed initialization)
/// is far from the optimum, as in graph_slam_test's planar far start; four iterations.
TEST_F(RunnerCli, GraphSlamSaysWhenGaussNewtonsCostRose) {
  const auto data = (dir / "far_start.txt").string();
  std::ofstream file(data);
  Eigen::Vector3d pose(8.0, 0.0, std::numbers::pi / 2);
  for (int k = 0; k < 60; ++k) {
    const Eigen::Vector3d next(pose.x() + 0.5 * std::cos(pose.z()), pose.y() + 0.5 * std::sin(pose.z()), pose.z() + 0.0625);
    const double heading_error = 5.0 * (std::sin(0.1 * (k + 1)) - std::sin(0.1 * k));
    file << "ODOMETRY " << k << " " << k + 1 << " 0.5 0 " << 0.0625 + heading_error << " 0.01 0 0 0.01 0 25\n";
    for (int j = 0; j < 12; ++j) {
      const Eigen::Vector2d to = Eigen::Vector2d(10.0 * std::cos(j * 0.52), 10.0 * std::sin(j * 0.52)) - next.head<2>();
      const Eigen::Vector2d z = Eigen::Rotation2Dd(-next.z()) * to;
      if (z.x() > 0.0 && z.norm() < 6.0) file << "LANDMARK " << k + 1 << " " << 100 + j << " " << z.x() << " " << z.y() << " 0.01 0 0.01\n";
    }
    pose = next;
  }
  file.close();
  const auto ini = (dir / "far_start.ini").string();
  std::ofstream(ini) << "[isam]\ngraph_window = 0\n[graph]\nmax_iterations = 4\ndamp_after_rise = false\n";
  const auto out = dir / "far_start_out";
  const auto plain = run_runner("-d " + data + " -b graph -c " + ini + " -o " + out.string(), dir);
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  EXPECT_NE(plain.out.find("Gauss-Newton's cost was lowest at iteration 1, whose estimate it kept, higher in the 3 "
                           "iterations after it; [graph] damp_after_rise = true descends"), std::string::npos) << plain.out;
  const std::string json = text_of(out / "summary.json");
  EXPECT_NE(json.find("\"optimization_earlier_iterate_runs\": 1, \"optimization_damped_runs\": 0"), std::string::npos) << json;
  // By default the rise at iteration 2 (plain Gauss-Newton's lowest cost was at iteration 1) is undone
  // and the steps after it damped, so the estimate is the last iterate's.
  std::ofstream(ini) << "[isam]\ngraph_window = 0\n[graph]\nmax_iterations = 4\n";
  const auto safeguarded = run_runner("-d " + data + " -b graph -c " + ini + " -o " + out.string(), dir);
  ASSERT_EQ(safeguarded.exit_code, 0) << safeguarded.err;
  EXPECT_NE(safeguarded.out.find("Gauss-Newton's cost rose at iteration 2: that step was undone and the steps after it "
                                 "damped (Levenberg-Marquardt)"), std::string::npos) << safeguarded.out;
  EXPECT_EQ(safeguarded.out.find("Gauss-Newton's cost was lowest"), std::string::npos) << safeguarded.out;
  const std::string damped_json = text_of(out / "summary.json");
  EXPECT_NE(damped_json.find("\"optimization_earlier_iterate_runs\": 0, \"optimization_damped_runs\": 1"), std::string::npos)
      << damped_json;
  std::ofstream(ini, std::ios::app) << "levenberg_marquardt = true\n";
  const auto damped = run_runner("-d " + data + " -b graph -c " + ini, dir);
  ASSERT_EQ(damped.exit_code, 0) << damped.err;
  EXPECT_NE(damped.out.find("GraphSLAM"), std::string::npos) << damped.out;
  EXPECT_EQ(damped.out.find("Gauss-Newton's cost"), std::string::npos) << damped.out;
}

TEST_F(RunnerCli, IniValuesReachTheBackEnds) {
  const auto ini = (dir / "good.ini").string();
  std::ofstream(ini) << "[ship]\nruns = 2\nsteps = 60\n[seif]\nmax_active = 3   // MRPT-style comment\n[fastslam]\nparticles = 7\n";
  const auto r = run_runner("-d ship -b seif,fastslam1 -c " + ini, dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("60 steps, 2 Monte Carlo run(s)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("SEIF-SLAM, 3 active"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("FastSLAM 1.0, 7 particles"), std::string::npos) << r.out;
}

TEST_F(RunnerCli, WithheldIdsAreAssociatedAndScoredByTheFiltersOnly) {
  const auto r = run_runner("-d ship --runs 1 -b ekf,graph --associate jcbb", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("ship: graph needs known ids, left out"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("EKF-SLAM"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("association: precision"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("GraphSLAM "), std::string::npos) << r.out;
  const auto bad = run_runner("-d ship --runs 1 -b ekf --associate magic", dir);
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_NE(bad.err.find("--associate: 'magic' is not one of known|nn|jcbb"), std::string::npos) << bad.err;
}

TEST_F(RunnerCli, RawlogWithoutIdsRunsEveryBackEndThatAssociates) {
  SEXTANT_REQUIRE_MRPT_DEMO("kf-slam_6D_demo_DA.rawlog");
  const auto r =
      run_runner("-d " + sextant::testing::mrpt_demo("kf-slam_6D_demo_DA.rawlog") + " -b ekf,graph,fastslam2 --associate jcbb", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("the log has no landmark ids; each frame's measurements took the ids of the distinct true "
                       "landmarks that explain them best from the true pose, which scores the association"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("graph needs known ids, left out"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("association: precision"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("FastSLAM 2.0"), std::string::npos) << r.out;
}

TEST_F(RunnerCli, IsamTextWithoutGroundTruthIsTimedAndWrittenNotScored) {
  const auto data = (dir / "loop.txt").string();
  std::ofstream file(data);
  file << "LANDMARK 0 1 2 1 10 0 10\n";
  for (int k = 0; k < 8; ++k)  // a square, the landmark seen from every pose
    file << "EDGE2 " << k << " " << k + 1 << " 1 0 1.5707963 50 0 0 50 0 100\nLANDMARK " << k + 1 << " 1 1 1 10 0 10\n";
  file.close();
  const auto out = dir / "isam_out";
  const auto r = run_runner("-d " + data + " -b ekf,graph -o " + out.string(), dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("no ground truth beside it"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("EKF-SLAM                               -          -"), std::string::npos) << r.out;
  EXPECT_TRUE(fs::exists(out / "loop" / "graph_map.csv"));
  const std::string json = text_of(out / "summary.json");
  EXPECT_NE(json.find("\"pose_mae\": null"), std::string::npos) << json;
}

/// A g2o file goes to sextant-pose-graph: its size, chi2 before and after, the optimized graph
/// written as g2o (read back at the printed chi2); a malformed file is one line naming file:line.
TEST_F(RunnerCli, PoseGraphFileIsOptimizedAndWrittenBack) {
  const auto data = (dir / "square.g2o").string();
  std::ofstream file(data);
  const char* info = " 100 0 0 100 0 400\n";
  for (int k = 0; k < 8; ++k) file << "VERTEX_SE2 " << k << " " << 0.1 * k << " " << -0.05 * k << " " << 0.2 * k << "\n";
  for (int k = 0; k < 8; ++k)  // a square driven twice, the last edge closing the loop
    file << "EDGE_SE2 " << k << " " << (k + 1) % 8 << " 1 0 " << (k % 2 ? "1.5707963" : "0") << info;
  file.close();
  const auto out = dir / "pose_graph_out";
  const auto r = run_runner("-d " + data + " -o " + out.string(), dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("2D g2o pose graph (SE(2)): 8 poses, 0 points; 8 edges: 7 odometry, 1 loop closures"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("| the file's vertices |"), std::string::npos) << r.out;
  const auto written = out / "square_optimized.g2o";
  ASSERT_TRUE(fs::exists(written)) << r.out;
  const auto read = sextant::io::read_pose_graph(written.string());
  char chi2[64];
  std::snprintf(chi2, sizeof chi2, "| %.10g |", read.planar.chi2());
  EXPECT_NE(r.out.find(chi2), std::string::npos) << chi2 << " not in\n" << r.out;
  std::ofstream(dir / "bad.g2o") << "VERTEX_SE2 0 0 0 0\nEDGE_SE2 0 3 1 0 0 1 0 0 1 0 1\n";
  expect_one_line_error("-d " + (dir / "bad.g2o").string(), {"bad.g2o:2: EDGE_SE2 names vertex 3"});
}

TEST_F(RunnerCli, TheDocsWorkedExampleFamilyRunsLikeAnyOther) {
  // docs/runner.md's "Add your own dataset": sextant-run/run_square.cpp and one registry line give a
  // family with the table, the files and one-line errors of every other (docs.runner_example keeps
  // the docs equal to the file).
  const auto out = dir / "square_out";
  const auto r = run_runner("-d square:3 -b ekf,graph -o " + out.string(), dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("== square:3: 328 steps, 40 landmarks in the ground truth"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("EKF-SLAM"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("GraphSLAM"), std::string::npos) << r.out;
  EXPECT_TRUE(fs::exists(out / "square:3" / "ekf_steps.csv"));
  EXPECT_TRUE(fs::exists(out / "square:3" / "graph.3Dscene"));
  expect_one_line_error("-d square:x", {"--dataset square:x", "whole number", "square:<seed>"});
  expect_one_line_error("-d square -d globe", {"--dataset globe: runs alone", "sextant-globe"});
}

}  // namespace
