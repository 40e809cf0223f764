// sextant-run's Monte Carlo studies beyond one process, as a cluster user runs them: three shards
// merged, and mpirun with two ranks, print the table one process prints (every score to the printed
// digit; the time columns are measurements of other processes); a missing or corrupt shard file ends
// the merge with an error naming the file and the seeds, never a table over fewer runs.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "support/run_program.hpp"

namespace {

namespace fs = std::filesystem;
using sextant::test::run_program;

const std::string kStudy = "--dataset ship --runs 5 --backend ekf,seif,fastslam2";

class StudyShards : public ::testing::Test {
 protected:
  fs::path dir = fs::temp_directory_path() / ("sextant_study_" + std::to_string(::getpid()) + "_" +
                                              ::testing::UnitTest::GetInstance()->current_test_info()->name());
  void SetUp() override { fs::create_directories(dir); }
  void TearDown() override { fs::remove_all(dir); }

  sextant::test::ProgramResult run(const std::string& arguments) {
    return run_program(std::string(SEXTANT_RUN_EXE) + " " + arguments, dir);
  }
};

/// The table's rows (lines that start with a back-end's name), each without its last two columns
/// (total seconds, microseconds per step), with the lines under them (association, skipped steps).
std::vector<std::string> scores_of_table(const std::string& output) {
  std::vector<std::string> rows;
  std::istringstream in(output);
  for (std::string line; std::getline(in, line);) {
    const bool row = line.starts_with("EKF-SLAM") || line.starts_with("SEIF-SLAM") || line.starts_with("FastSLAM") ||
                     line.starts_with("GraphSLAM");
    if (!row) continue;
    std::istringstream tokens(line);
    std::vector<std::string> words;
    for (std::string w; tokens >> w;) words.push_back(w);
    words.resize(words.size() - 2);
    std::string kept;
    for (const auto& w : words) kept += w + " ";
    rows.push_back(kept);
  }
  return rows;
}

TEST_F(StudyShards, ThreeShardsMergedPrintTheTableOfOneProcess) {
  const auto whole = run(kStudy + " --out " + (dir / "whole").string());
  ASSERT_EQ(whole.exit_code, 0) << whole.err;
  const auto expected = scores_of_table(whole.out);
  ASSERT_EQ(expected.size(), 3u) << whole.out;
  std::string shard_dirs;
  for (int i = 0; i < 3; ++i) {
    const auto shard_dir = dir / ("shard" + std::to_string(i));
    const auto r = run(kStudy + " --shard " + std::to_string(i) + "/3 --out " + shard_dir.string());
    ASSERT_EQ(r.exit_code, 0) << r.err;
    ASSERT_TRUE(fs::exists(shard_dir / ("records-" + std::to_string(i) + "-of-3.tsv")));
    EXPECT_NE(r.out.find("(this shard " + std::to_string(i) + "/3"), std::string::npos) << r.out;
    shard_dirs += " " + shard_dir.string();
  }
  const auto merged = run("--merge" + shard_dirs);
  ASSERT_EQ(merged.exit_code, 0) << merged.err;
  EXPECT_EQ(scores_of_table(merged.out), expected) << merged.out << "\nagainst\n" << whole.out;
  // the one process's own records merge to its table, times included
  const auto again = run("--merge " + (dir / "whole").string());
  ASSERT_EQ(again.exit_code, 0) << again.err;
  const auto rows_with_times = [](const std::string& out) {
    std::vector<std::string> rows;
    std::istringstream in(out);
    for (std::string line; std::getline(in, line);)
      if (line.starts_with("EKF-SLAM") || line.starts_with("SEIF") || line.starts_with("FastSLAM")) rows.push_back(line);
    return rows;
  };
  EXPECT_EQ(rows_with_times(again.out), rows_with_times(whole.out));
}

/// What the table says below a row travels through the records: a GraphSLAM that stopped at its
/// iteration limit in every run says so, counted over the merged shards' runs.
TEST_F(StudyShards, UnconvergedOptimizationsAreCountedOverTheMergedShards) {
  std::ofstream(dir / "one_iteration.ini") << "[ship]\nsteps = 60\n[graph]\nmax_iterations = 1\n";
  const std::string study = "--dataset ship --runs 4 --backend graph -c " + (dir / "one_iteration.ini").string();
  std::string shard_dirs;
  for (int i = 0; i < 2; ++i) {
    const auto shard_dir = dir / ("shard" + std::to_string(i));
    ASSERT_EQ(run(study + " --shard " + std::to_string(i) + "/2 --out " + shard_dir.string()).exit_code, 0);
    shard_dirs += " " + shard_dir.string();
  }
  const auto merged = run("--merge" + shard_dirs);
  ASSERT_EQ(merged.exit_code, 0) << merged.err;
  EXPECT_NE(merged.out.find("optimization stopped at its limit of 1 iteration before converging in 4 of 4 runs"),
            std::string::npos) << merged.out;
}

TEST_F(StudyShards, AMissingOrCorruptShardFileIsAnErrorNamingTheFileAndSeeds) {
  for (int i : {0, 2}) {
    const auto r = run(kStudy + " --shard " + std::to_string(i) + "/3 --out " + dir.string());
    ASSERT_EQ(r.exit_code, 0) << r.err;
  }
  auto merged = run("--merge " + dir.string());
  EXPECT_EQ(merged.exit_code, 1);
  EXPECT_NE(merged.err.find("misses shard files: records-1-of-3.tsv (seeds 2..3)"), std::string::npos) << merged.err;
  EXPECT_EQ(scores_of_table(merged.out).size(), 0u) << "no table over fewer runs";

  const auto shard2 = dir / "records-2-of-3.tsv";
  std::stringstream text;
  text << std::ifstream(shard2).rdbuf();
  const std::string full = text.str();
  std::ofstream(shard2) << full.substr(0, full.size() * 2 / 3);  // cut off mid-file
  const auto r = run(kStudy + " --shard 1/3 --out " + dir.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  merged = run("--merge " + dir.string());
  EXPECT_EQ(merged.exit_code, 1);
  EXPECT_NE(merged.err.find(shard2.string() + ":"), std::string::npos) << merged.err;
  EXPECT_EQ(merged.err.find('\n'), merged.err.size() - 1) << "one line";

  const auto other = run("--dataset ship --runs 5 --backend ekf --shard 2/3 --out " + dir.string());
  ASSERT_EQ(other.exit_code, 0) << other.err;
  merged = run("--merge " + dir.string());
  EXPECT_EQ(merged.exit_code, 1);
  EXPECT_NE(merged.err.find("another study"), std::string::npos) << merged.err;
}

TEST_F(StudyShards, ShardOptionsThatCannotWorkAreRefused) {
  auto r = run(kStudy + " --shard 3/3 --out " + dir.string());
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("0 <= i < K"), std::string::npos) << r.err;
  r = run(kStudy + " --shard 0/3");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("needs --out DIR"), std::string::npos) << r.err;
  r = run("--dataset no-such.rawlog --shard 0/3 --out " + dir.string());
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("not a Monte Carlo over seeds"), std::string::npos) << r.err;
  r = run("--merge " + (dir / "none").string());
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("no such record file or directory"), std::string::npos) << r.err;
}

TEST_F(StudyShards, MpirunWithTwoRanksPrintsTheTableOfOneProcess) {
#ifndef SEXTANT_MPIEXEC
  GTEST_SKIP() << "built without MPI (Debian: libopenmpi-dev openmpi-bin)";
#else
  const auto whole = run(kStudy);
  ASSERT_EQ(whole.exit_code, 0) << whole.err;
  // root may run mpirun only when it says so (CI runs as root)
  const std::string mpirun = std::string("OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 ") + SEXTANT_MPIEXEC +
                             " -np 2 --oversubscribe " + SEXTANT_RUN_EXE + " " + kStudy + " --out " + dir.string();
  const auto ranks = run_program(mpirun, dir);
  ASSERT_EQ(ranks.exit_code, 0) << ranks.out << ranks.err;
  EXPECT_EQ(scores_of_table(ranks.out), scores_of_table(whole.out)) << ranks.out << "\nagainst\n" << whole.out;
  EXPECT_EQ(scores_of_table(ranks.out).size(), 3u) << "rank 0 alone prints the table";
  EXPECT_TRUE(fs::exists(dir / "records-0-of-1.tsv")) << "rank 0 writes the whole study's records";
#endif
}

/// The table lines of a study program (Markdown rows after the header), without the last column
/// (run times).
std::vector<std::string> study_rows(const std::string& output) {
  std::vector<std::string> rows;
  std::istringstream in(output);
  for (std::string line; std::getline(in, line);)
    if (line.starts_with("| ") && !line.starts_with("| position MAE")) rows.push_back(line.substr(0, line.rfind("| ", line.size() - 3)));
  return rows;
}

TEST_F(StudyShards, TheGlobeStudyInShardsAndOverMpiRanksPrintsTheTableOfOneProcess) {
  const std::string study = std::string(SEXTANT_GLOBE_STUDY_EXE) + " --runs 4 --steps 12";
  const auto whole = run_program(study, dir);
  ASSERT_EQ(whole.exit_code, 0) << whole.err;
  ASSERT_EQ(study_rows(whole.out).size(), 1u) << whole.out;
  for (int i = 0; i < 2; ++i) {
    const auto r = run_program(study + " --shard " + std::to_string(i) + "/2 --out " + dir.string(), dir);
    ASSERT_EQ(r.exit_code, 0) << r.err;
  }
  const auto merged = run_program(std::string(SEXTANT_GLOBE_STUDY_EXE) + " --merge " + dir.string(), dir);
  ASSERT_EQ(merged.exit_code, 0) << merged.err;
  EXPECT_EQ(study_rows(merged.out), study_rows(whole.out)) << merged.out << "\nagainst\n" << whole.out;
#ifdef SEXTANT_MPIEXEC
  const auto ranks = run_program(std::string("OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 ") + SEXTANT_MPIEXEC +
                                     " -np 2 --oversubscribe " + study, dir);
  ASSERT_EQ(ranks.exit_code, 0) << ranks.out << ranks.err;
  EXPECT_EQ(study_rows(ranks.out), study_rows(whole.out)) << ranks.out << "\nagainst\n" << whole.out;
#endif
}

}  // namespace
