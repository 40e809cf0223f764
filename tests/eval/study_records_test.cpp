// A Monte Carlo study split into shards: the seeds each shard holds, record files that read back to
// the same doubles, the average of records equal to the bit to the average of the runs, and a merge
// that refuses anything but one whole study (eval/study_records.hpp, eval/seed_shards.hpp).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <sextant/eval/experiment.hpp>
#include <sextant/eval/study_records.hpp>
#include <set>
#include <sstream>

namespace {

using namespace sextant;
using namespace sextant::eval;

TEST(SeedShards, EveryShardCountSplitsTheSeedsOnceInBlocksOfNearlyEqualSize) {
  for (int runs : {1, 2, 7, 20, 200})
    for (int count : {1, 2, 3, 7, 64}) {
      std::set<std::uint64_t> seen;
      int smallest = runs, largest = 0;
      std::uint64_t next = 100;
      for (int i = 0; i < count; ++i) {
        const auto r = seeds_of({i, count}, runs, 100);
        EXPECT_EQ(r.first, next) << "contiguous blocks in shard order";
        for (int k = 0; k < r.count; ++k) EXPECT_TRUE(seen.insert(r.first + k).second);
        next = r.first + r.count;
        smallest = std::min(smallest, r.count);
        largest = std::max(largest, r.count);
      }
      EXPECT_EQ(seen.size(), static_cast<std::size_t>(runs)) << runs << " runs, " << count << " shards";
      EXPECT_EQ(next, 100u + runs);
      EXPECT_LE(largest - smallest, 1);
    }
}

TEST(SeedShards, ParseRefusesWhatIsNotAShard) {
  EXPECT_EQ(parse_shard("2/5"), (Shard{2, 5}));
  for (const char* bad : {"", "3", "1/", "/3", "3/3", "-1/3", "1/0", "a/b", "1/3x", "1.5/3"})
    EXPECT_THROW(parse_shard(bad), invalid_input_error) << "'" << bad << "'";
}

/// A run with random errors (some runs with an infinite NEES, a failed step).
RunSummary<Eigen::Vector2d> random_run(std::mt19937_64& rng, std::size_t steps) {
  std::lognormal_distribution<double> value(0.0, 1.5);
  RunSummary<Eigen::Vector2d> r;
  for (std::size_t k = 0; k < steps; ++k) {
    r.pose_error.push_back(value(rng));
    r.pose_error_aligned.push_back(value(rng));
    r.pose_nees.push_back(value(rng) * 2.0);
    r.pose_support.push_back(rng() % 3 == 0 ? 2.5 * value(rng) : std::numeric_limits<double>::infinity());
    r.seconds.push_back(1e-4 * value(rng));
  }
  for (int i = 0; i < 7; ++i) {
    r.map_error.push_back(value(rng));
    r.map_error_aligned.push_back(value(rng));
    r.map_nees.push_back(value(rng) * 2.0);
  }
  r.map_error_over_time = value(rng);
  r.total_seconds = value(rng);
  if (rng() % 5 == 0) r.failures.record(3, false, error("S is not positive definite\tat\\ step 3\n"));
  return r;
}

/// `count` random runs of 5 steps from generator seed `seed`.
std::vector<RunSummary<Eigen::Vector2d>> random_runs(std::uint64_t seed, int count) {
  std::mt19937_64 rng(seed);
  std::vector<RunSummary<Eigen::Vector2d>> runs;
  for (int i = 0; i < count; ++i) runs.push_back(random_run(rng, 5));
  return runs;
}

std::vector<StudyRecord> records_of(const std::vector<RunSummary<Eigen::Vector2d>>& runs, std::uint64_t first_seed) {
  std::vector<StudyRecord> records;
  for (std::size_t i = 0; i < runs.size(); ++i)
    records.push_back({"ship", "ekf", "EKF-SLAM", 2, first_seed + i, scores_of(runs[i], 2, 2), {}, {}});
  return records;
}

void expect_same_bits(double a, double b, const char* what) {
  EXPECT_EQ(std::memcmp(&a, &b, sizeof a), 0) << what << ": " << a << " against " << b;
}

void expect_same_summary(const Summary& a, const Summary& b) {
  for (auto field : {&Summary::pose_mae, &Summary::map_mae, &Summary::map_mae_over_time, &Summary::pose_rmse,
                     &Summary::pose_rmse_aligned, &Summary::pose_mae_aligned, &Summary::map_mae_aligned,
                     &Summary::pose_nees_inside, &Summary::map_nees_inside, &Summary::total_seconds,
                     &Summary::seconds_per_step, &Summary::pose_anees, &Summary::pose_mae_std, &Summary::map_mae_std,
                     &Summary::pose_undersampled, &Summary::pose_anees_supported})
    expect_same_bits(a.*field, b.*field, "a score");
  ASSERT_EQ(a.anees_interval.has_value(), b.anees_interval.has_value());
  if (a.anees_interval) {
    expect_same_bits(a.anees_interval->lower, b.anees_interval->lower, "ANEES interval");
    expect_same_bits(a.anees_interval->upper, b.anees_interval->upper, "ANEES interval");
  }
  EXPECT_EQ(a.failed_steps, b.failed_steps);
  EXPECT_EQ(a.first_failure, b.first_failure);
}

std::vector<RecordFile> written_and_read(const std::vector<StudyRecord>& all, int shards, const std::string& study = "s") {
  std::vector<RecordFile> files;
  const int runs = static_cast<int>(all.size());
  for (int i = shards - 1; i >= 0; --i) {  // any order
    const auto seeds = seeds_of({i, shards}, runs, all.front().seed);
    std::vector<StudyRecord> part;
    for (const auto& r : all)
      if (seeds.contains(r.seed)) part.push_back(r);
    std::stringstream text;
    write_records(text, {"sextant-run", study, runs, all.front().seed, {i, shards}}, part);
    files.push_back(parse_records(text, record_file_name({i, shards})));
  }
  return files;
}

TEST(RunScores, AStepWhosePoseRestsOnTooFewParticlesIsUndersampledAndNeverInside) {
  // 2 dof: a covariance from fewer than 3 effective particles cannot span the pose (bound 5.991).
  RunSummary<Eigen::Vector2d> r;
  r.pose_nees = {1.0, 100.0, 2.0, 3.0, 4.0};
  r.pose_support = {std::numeric_limits<double>::infinity(), 50.0, 2.9, 3.0, 1.0};
  const auto s = scores_of(r, 2, 2);
  EXPECT_DOUBLE_EQ(s.pose_undersampled, 2.0 / 5.0);  // steps 2 and 4
  EXPECT_DOUBLE_EQ(s.pose_nees_inside, 2.0 / 5.0);   // steps 0 and 3: 1 is above the bound
  EXPECT_DOUBLE_EQ(s.pose_anees, 22.0);              // the raw average, kept for the record
  EXPECT_DOUBLE_EQ(s.pose_anees_supported, 104.0 / 3.0);  // steps 0, 1, 3
  r.pose_support.clear();                            // a Gaussian back-end's run
  const auto gaussian = scores_of(r, 2, 2);
  EXPECT_EQ(gaussian.pose_undersampled, 0.0);
  EXPECT_DOUBLE_EQ(gaussian.pose_nees_inside, 4.0 / 5.0);
  EXPECT_DOUBLE_EQ(gaussian.pose_anees_supported, gaussian.pose_anees);
  r.pose_support.assign(5, 1.0);  // every step collapsed: no supported average
  EXPECT_TRUE(std::isnan(scores_of(r, 2, 2).pose_anees_supported));
}

TEST(RunScores, ARunWithNothingToScoreScoresNoneNotZero) {
  // A back-end whose every step failed (GraphSLAM on exact odometry): no pose after the start, no
  // map. Zeros would read as a perfect run; every score is NaN, which the table prints as "-".
  RunSummary<Eigen::Vector2d> r;
  r.seconds.assign(4, 1e-3);
  for (std::size_t k = 0; k < 4; ++k) r.failures.record(k, true, numerical_error("singular"));
  const auto s = scores_of(r, 2, 2);
  for (double score : {s.pose_mae, s.pose_rmse, s.pose_rmse_aligned, s.pose_mae_aligned, s.map_mae, s.map_mae_over_time,
                       s.map_mae_aligned, s.pose_nees_inside, s.map_nees_inside, s.pose_anees, s.pose_undersampled,
                       s.pose_anees_supported})
    EXPECT_TRUE(std::isnan(score)) << score;
  EXPECT_EQ(s.failed_steps, 4u);
  const auto average = summarize(std::vector{s, s}, 2);
  EXPECT_TRUE(std::isnan(average.pose_mae) && std::isnan(average.map_mae) && std::isnan(average.pose_anees));
  EXPECT_FALSE(average.anees_interval);
  EXPECT_EQ(average.failed_steps, 8u);
}

TEST(StudyRecords, MergedShardsAverageToTheBitLikeTheRunsInOneProcess) {
  std::mt19937_64 rng(7);
  std::vector<RunSummary<Eigen::Vector2d>> runs;
  for (int i = 0; i < 23; ++i) runs.push_back(random_run(rng, 50 + i));
  runs[4].pose_nees[2] = std::numeric_limits<double>::infinity();  // a covariance that was not positive definite
  const auto whole = summarize(runs, 2, 2);
  for (int shards : {1, 2, 3, 5, 23}) {
    const auto merged = merge_records(written_and_read(records_of(runs, 40), shards));
    ASSERT_EQ(merged.size(), runs.size());
    std::vector<RunScores> scores;
    for (std::size_t i = 0; i < merged.size(); ++i) {
      EXPECT_EQ(merged[i].seed, 40 + i) << "seed order";
      scores.push_back(merged[i].scores);
    }
    expect_same_summary(summarize(scores, 2), whole);
  }
}

TEST(StudyRecords, NumbersStringsAndExtrasReadBackExactly) {
  StudyRecord r{"da\tta", "c\\ell", "label, with ; and = and \n", 6, 1ull << 52, {}, {{"a", 0.1}, {"b", -3e-300}}, "failed: x\ty"};
  r.scores.pose_mae = std::numeric_limits<double>::infinity();
  r.scores.pose_rmse = -std::numeric_limits<double>::infinity();
  r.scores.pose_anees = std::nextafter(1.0, 2.0);
  r.scores.map_mae = std::numeric_limits<double>::denorm_min();
  r.scores.first_failure = "step 3: update: S\\n";
  std::stringstream text;
  write_records(text, {"p", "study with\ttab", 1, 1ull << 52, {0, 1}}, {r});
  const auto back = parse_records(text, "t");
  ASSERT_EQ(back.records.size(), 1u);
  const auto& b = back.records.front();
  EXPECT_EQ(back.header.study, "study with\ttab");
  EXPECT_EQ(b.dataset, r.dataset);
  EXPECT_EQ(b.cell, r.cell);
  EXPECT_EQ(b.label, r.label);
  EXPECT_EQ(b.seed, r.seed);
  EXPECT_EQ(b.failure, r.failure);
  EXPECT_EQ(b.scores.first_failure, r.scores.first_failure);
  expect_same_bits(b.scores.pose_mae, r.scores.pose_mae, "inf");
  expect_same_bits(b.scores.pose_rmse, r.scores.pose_rmse, "-inf");
  expect_same_bits(b.scores.pose_anees, r.scores.pose_anees, "1 + ulp");
  expect_same_bits(b.scores.map_mae, r.scores.map_mae, "denormal");
  ASSERT_EQ(b.extras.size(), 2u);
  expect_same_bits(b.extra("b"), -3e-300, "extra");
  EXPECT_TRUE(std::isnan(b.extra("none")));
}

std::string file_text(const std::vector<StudyRecord>& records, Shard shard, int runs) {
  std::stringstream text;
  write_records(text, {"sextant-run", "s", runs, 1, shard}, records);
  return text.str();
}

std::string parse_error_of(const std::string& text) {
  std::istringstream in(text);
  try {
    parse_records(in, "shard.tsv");
  } catch (const parse_error& e) {
    return e.what();
  }
  return "no error";
}

TEST(StudyRecords, CorruptFilesNameTheFileAndLine) {
  std::mt19937_64 rng(1);
  const auto records = records_of({random_run(rng, 5), random_run(rng, 5)}, 1);
  const auto good = file_text(records, {0, 1}, 2);
  EXPECT_EQ(parse_error_of(good), "no error");
  const auto truncated = good.substr(0, good.rfind("end\t"));
  EXPECT_NE(parse_error_of(truncated).find("shard.tsv: truncated: no end line after 2 records"), std::string::npos);
  EXPECT_NE(parse_error_of(good.substr(0, good.size() / 2)).find("shard.tsv:"), std::string::npos);
  auto bad_number = good;
  bad_number.replace(bad_number.find("\t5\t"), 3, "\tx\t");  // the first record's steps
  EXPECT_NE(parse_error_of(bad_number).find("shard.tsv:8: steps: 'x'"), std::string::npos) << parse_error_of(bad_number);
  auto wrong_count = good;
  wrong_count.replace(wrong_count.rfind("end\t2"), 5, "end\t3");
  EXPECT_NE(parse_error_of(wrong_count).find("counts 3 records, the file holds 2"), std::string::npos);
  EXPECT_NE(parse_error_of("hello\n").find("shard.tsv:1: not a sextant record file"), std::string::npos);
}

std::string merge_error_of(std::vector<RecordFile> files) {
  try {
    merge_records(std::move(files));
  } catch (const invalid_input_error& e) {
    return e.what();
  }
  return "no error";
}

TEST(StudyRecords, MergeRefusesAMissingShardNamingItsFileAndSeeds) {
  const auto runs = random_runs(2, 9);
  auto files = written_and_read(records_of(runs, 1), 3);  // shards 2, 1, 0
  files.erase(files.begin() + 1);
  EXPECT_NE(merge_error_of(files).find("misses shard files: records-1-of-3.tsv (seeds 4..6)"), std::string::npos)
      << merge_error_of(files);
}

TEST(StudyRecords, MergeRefusesAShardThatLacksRunsNamingTheFileAndSeeds) {
  const auto runs = random_runs(3, 9);
  auto files = written_and_read(records_of(runs, 1), 3);
  files[1].records.erase(files[1].records.begin());  // shard 1 without seed 4
  EXPECT_NE(merge_error_of(files).find("records-1-of-3.tsv: ship/ekf lacks seeds 4 of shard 1/3"), std::string::npos)
      << merge_error_of(files);
  files = written_and_read(records_of(runs, 1), 3);
  files[0].records.push_back(files[0].records.back());
  EXPECT_NE(merge_error_of(files).find("seed 9 of ship/ekf twice"), std::string::npos) << merge_error_of(files);
  files = written_and_read(records_of(runs, 1), 3);
  files[2].records.front().seed = 9;  // shard 0 holding a seed of shard 2
  EXPECT_NE(merge_error_of(files).find("seed 9 is not one of shard 0/3 (seeds 1..3)"), std::string::npos)
      << merge_error_of(files);
}

TEST(StudyRecords, MergeRefusesShardsOfAnotherStudyOrTheSameShardTwice) {
  const auto runs = random_runs(4, 4);
  auto files = written_and_read(records_of(runs, 1), 2);
  auto other = written_and_read(records_of(runs, 1), 2, "--runs 4 -c other.ini");
  files[0] = other[0];
  EXPECT_NE(merge_error_of(files).find("another study"), std::string::npos) << merge_error_of(files);
  files = written_and_read(records_of(runs, 1), 2);
  files.push_back(files[0]);
  files.back().name = "copy.tsv";
  EXPECT_NE(merge_error_of(files).find("are both shard 1/2"), std::string::npos) << merge_error_of(files);
  EXPECT_NE(merge_error_of({}).find("no record files"), std::string::npos);
}

}  // namespace
