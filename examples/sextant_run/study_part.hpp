#pragma once
// How this process takes part in a Monte Carlo study (docs/monte_carlo_clusters.md): it runs every
// seed; or one shard of them (--shard i/K), writing their records for --merge; or, as one of
// mpirun's ranks, the shard of its rank, gathered on rank 0, which prints the whole table. In every
// case the table is made from the runs' records (eval/study_records.hpp), so all three print the same
// scores. Shared by the runner programs and the study programs (sextant-seif-study, ...).
#include <cstdint>
#include <string>
#include <vector>

#include <sextant/eval/study_records.hpp>

namespace sextant::runner {

struct StudyPart {
  enum class Mode { whole, shard, mpi };
  Mode mode = Mode::whole;
  eval::Shard shard;    ///< this process's share of the seeds
  unsigned threads = 0;  ///< threads for its runs (0: every core; MPI: the cores over the ranks on this machine)
  std::string program;
  std::string study;  ///< what identifies the study: the command line but --shard/--out/--plots, and the config file's hash

  /// The seeds this process runs of a study of `runs` runs from `first_seed`.
  eval::SeedRange seeds(int runs, std::uint64_t first_seed) const { return eval::seeds_of(shard, runs, first_seed); }

  /// Whether this process prints tables (every one but MPI's ranks other than 0).
  bool prints() const { return mode != Mode::mpi || shard.index == 0; }
};

/// The part this process plays, from --shard, the MPI launch (mpi_world.hpp) and the command line;
/// at MPI's ranks other than 0, stdout goes to /dev/null.
StudyPart study_part(const std::string& program, const std::string& shard, const std::string& out, int argc,
                     char** argv, const std::string& config_path);

/// The records the table of a study is made of, from this process's `mine` (the seeds of
/// part.seeds(runs, first_seed)): whole: `mine` (also written to out/records-0-of-1.tsv with --out);
/// shard: `mine`, written to out/records-i-of-K.tsv; MPI: every rank's, merged, at rank 0 (which
/// writes them with --out as one process would) and none at the others.
std::vector<eval::StudyRecord> study_records(const StudyPart& part, std::vector<eval::StudyRecord> mine, int runs,
                                             std::uint64_t first_seed, const std::string& out);

/// --merge: the records of the study whose record files (or directories of them) are `paths`, all
/// of `program`, merged (eval::merge_records); `header` receives the study's header.
std::vector<eval::StudyRecord> merged_records(const std::string& program, const std::vector<std::string>& paths,
                                              eval::StudyHeader& header, std::size_t& files);

}  // namespace sextant::runner
