#pragma once
// What every Monte Carlo study program (sextant-seif-study, sextant-fastslam-study,
// sextant-globe-study) shares: --runs, --seed, --shard, --out and --merge, and running its cells as
// this process's part of the study (sextant_run/study_part.hpp): every seed, a shard of them, or an
// MPI rank's; the program prints its table from the records StudyRun::finish returns.
#include <CLI/CLI.hpp>
#include <cstdint>
#include <exception>
#include <sextant/eval/monte_carlo.hpp>
#include <string>
#include <vector>

#include "mpi_world.hpp"
#include "study_part.hpp"

namespace sextant::runner {

struct StudyCommandLine {
  int runs = 20;
  std::uint64_t seed = 1;
  std::string shard, out;
  std::vector<std::string> merge;

  void add_to(CLI::App& app) {
    app.add_option("--runs", runs, "Monte Carlo runs")->check(CLI::Range(2, 100000))->capture_default_str();
    app.add_option("--seed", seed, "first seed")->capture_default_str();
    app.add_option("--shard", shard, "i/K: run only shard i (from 0) of K of the seeds, records to --out "
                                     "(records-i-of-K.tsv); under mpirun each rank takes its shard by itself");
    app.add_option("--out", out, "directory for the record file");
    app.add_option("--merge", merge, "record files or directories of one study's shards: print its table");
  }
};

/// This process's part of a study program's run: add its cells, then print what finish() returns.
class StudyRun {
 public:
  StudyRun(const char* program, const StudyCommandLine& cli, int argc, char** argv) : cli_(cli) {
    if (cli.merge.empty()) part_ = study_part(program, cli.shard, cli.out, argc, argv, "");
    else if (!cli.shard.empty()) throw invalid_input_error("--merge prints a study from its records: no --shard with it");
    part_.program = program;
  }
  StudyRun(const StudyRun&) = delete;
  StudyRun& operator=(const StudyRun&) = delete;
  /// Leaves MPI; a rank that ends by an exception ends them all (the others would wait for it).
  ~StudyRun() { mpi::leave(std::uncaught_exceptions() > 0); }

  /// Runs experiment(seed) -> eval::StudyRecord over this process's seeds (nothing when merging).
  template <class Experiment>
  void add_cell(Experiment experiment) {
    if (!cli_.merge.empty()) return;
    const auto seeds = part_.seeds(cli_.runs, cli_.seed);
    auto runs = eval::monte_carlo(seeds.count, seeds.first, experiment, part_.threads);
    records_.insert(records_.end(), runs.begin(), runs.end());
  }

  /// The records to print: this process's (whole or shard), every rank's at MPI's rank 0 (none at
  /// the others), or the merged files'.
  std::vector<eval::StudyRecord> finish() {
    if (cli_.merge.empty()) return study_records(part_, std::move(records_), cli_.runs, cli_.seed, cli_.out);
    eval::StudyHeader header;
    std::size_t files = 0;
    auto merged = merged_records(part_.program, cli_.merge, header, files);
    cli_.runs = header.runs;
    cli_.seed = header.first_seed;
    std::printf("merged %zu record file(s) of %d shard(s): %d runs from seed %llu (%s)\n\n", files, header.shard.count,
                header.runs, static_cast<unsigned long long>(header.first_seed), header.study.c_str());
    return merged;
  }

  const StudyPart& part() const { return part_; }
  int runs() const { return cli_.runs; }                 ///< the study's (after finish(): the merged files')
  std::uint64_t first_seed() const { return cli_.seed; }  ///< likewise

 private:
  StudyCommandLine cli_;
  StudyPart part_;
  std::vector<eval::StudyRecord> records_;
};

/// "a [l, u]" for an ANEES and its interval; "a" alone when there is none (fewer than 2 runs, an
/// infinite ANEES); "collapsed at p% (others: a)" where a particle cloud's pose rested on fewer than
/// dof + 1 effective particles at some steps (eval::RunScores::pose_undersampled).
inline std::string anees_with_interval(const eval::Summary& s, const char* format, int interval_decimals) {
  char text[96];
  if (s.pose_undersampled > 0.0) {
    std::snprintf(text, sizeof text, "collapsed at %.1f%% of the steps (others: ", 100.0 * s.pose_undersampled);
    std::string out = text;
    std::snprintf(text, sizeof text, format, s.pose_anees_supported);
    return out + text + ")";
  }
  std::snprintf(text, sizeof text, format, s.pose_anees);
  std::string out = text;
  if (s.anees_interval) {
    std::snprintf(text, sizeof text, " [%.*f, %.*f]", interval_decimals, s.anees_interval->lower, interval_decimals,
                  s.anees_interval->upper);
    out += text;
  }
  return out;
}

/// The records of one cell, in seed order.
inline std::vector<eval::StudyRecord> cell_records(const std::vector<eval::StudyRecord>& records, const std::string& cell) {
  std::vector<eval::StudyRecord> out;
  for (const auto& r : records)
    if (r.cell == cell) out.push_back(r);
  return out;
}

/// Their scores, in order (for eval::summarize).
inline std::vector<eval::RunScores> scores_of(const std::vector<eval::StudyRecord>& records) {
  std::vector<eval::RunScores> out;
  for (const auto& r : records) out.push_back(r.scores);
  return out;
}

}  // namespace sextant::runner
