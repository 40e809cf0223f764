// How this process takes part in a Monte Carlo study (study_part.hpp), compiled once for the runner
// and the study programs.
#include "study_part.hpp"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <thread>

#include "mpi_world.hpp"

namespace sextant::runner {
namespace {

/// FNV-1a of a file's bytes, as hex; "none" without a file, "unreadable" for what is not a regular
/// file (the config's reader then says what is wrong with it).
std::string file_hash(const std::string& path) {
  if (path.empty()) return "none";
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) return "unreadable";
  std::ifstream in(path, std::ios::binary);
  std::uint64_t h = 1469598103934665603ull;
  for (std::istreambuf_iterator<char> it(in), end; it != end; ++it) {
    h ^= static_cast<unsigned char>(*it);
    h *= 1099511628211ull;
  }
  char text[24];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(h));
  return text;
}

/// The command line without what differs between the shards of one study.
std::string study_arguments(int argc, char** argv) {
  std::string out;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--shard" || a == "--out" || a == "-o") {
      ++i;
      continue;
    }
    if (a == "--plots" || a.starts_with("--shard=") || a.starts_with("--out=")) continue;
    out += (out.empty() ? "" : " ") + a;
  }
  return out;
}

/// Every rank's records (their record files' text) merged, at rank 0.
std::vector<eval::StudyRecord> gathered_records(const std::string& mine) {
  const auto texts = mpi::gather(mine);
  std::vector<eval::RecordFile> files;
  for (std::size_t r = 0; r < texts.size(); ++r) {
    std::istringstream in(texts[r]);
    files.push_back(eval::parse_records(in, "rank " + std::to_string(r)));
  }
  return files.empty() ? std::vector<eval::StudyRecord>{} : eval::merge_records(std::move(files));
}

}  // namespace

StudyPart study_part(const std::string& program, const std::string& shard, const std::string& out, int argc,
                     char** argv, const std::string& config_path) {
  StudyPart part;
  part.program = program;
  part.study = study_arguments(argc, argv) + "; config " + file_hash(config_path);
  const mpi::World world = mpi::join();
  if (world.size > 1 && world.rank != 0) std::freopen("/dev/null", "w", stdout);  // rank 0 prints the table
  if (world.size > 1) {
    if (!shard.empty()) throw invalid_input_error("--shard: not with mpirun, which gives each rank its shard");
    part.mode = StudyPart::Mode::mpi;
    part.shard = {world.rank, world.size};
    part.threads = std::max(1u, std::thread::hardware_concurrency() / static_cast<unsigned>(world.local_size));
  } else if (!shard.empty()) {
    part.shard = eval::parse_shard(shard);
    if (out.empty()) throw invalid_input_error("--shard " + shard + ": needs --out DIR for its record file");
    part.mode = StudyPart::Mode::shard;
  }
  return part;
}

std::vector<eval::StudyRecord> study_records(const StudyPart& part, std::vector<eval::StudyRecord> mine, int runs,
                                           std::uint64_t first_seed, const std::string& out) {
  const eval::StudyHeader header{part.program, part.study, runs, first_seed, part.shard};
  if (part.mode == StudyPart::Mode::mpi) {
    std::ostringstream text;
    eval::write_records(text, header, mine);
    auto all = gathered_records(text.str());
    if (part.prints() && !out.empty()) {  // rank 0: the whole study's records, as one process would write them
      eval::StudyHeader whole = header;
      whole.shard = {};
      std::printf("wrote %s\n", eval::write_record_file(out, whole, all).c_str());
    }
    return all;
  }
  if (!out.empty()) std::printf("wrote %s\n", eval::write_record_file(out, header, mine).c_str());
  return mine;
}

std::vector<eval::StudyRecord> merged_records(const std::string& program, const std::vector<std::string>& paths,
                                              eval::StudyHeader& header, std::size_t& count) {
  std::vector<eval::RecordFile> files;
  for (const auto& path : paths)
    for (const auto& file : eval::record_files_in(path)) files.push_back(eval::read_records(file));
  for (const auto& f : files)
    if (f.header.program != program)
      throw invalid_input_error(f.name + ": records of " + f.header.program + ", not of " + program + " (merge them there)");
  header = files.empty() ? eval::StudyHeader{} : files.front().header;
  count = files.size();
  return eval::merge_records(std::move(files));
}

}  // namespace sextant::runner
