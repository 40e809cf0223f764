#pragma once
/// \file The record file of a Monte Carlo study's runs, and the merge of many of them. Each run of a
/// study (a seed of a cell: a data set and a back-end with its settings) is kept as the numbers its
/// average needs (RunScores), written so that reading gives back the same doubles (%.17g); shards of a
/// study run anywhere write one file each (records-i-of-K.tsv), and their merge, averaged in seed
/// order, equals the table one process prints, to the bit. The format is documented in
/// docs/monte_carlo_clusters.md.

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "sextant/core/error.hpp"
#include "sextant/eval/run_scores.hpp"
#include "sextant/eval/seed_shards.hpp"

namespace sextant::eval {

/// What a record file belongs to: the program, the study (its settings: only files of one study
/// merge), the seeds of the whole study and the shard the file holds.
struct StudyHeader {
  std::string program, study;
  int runs = 0;
  std::uint64_t first_seed = 0;
  Shard shard;
};

/// One run of one cell of a study.
struct StudyRecord {
  std::string dataset, cell, label;  ///< the cell: a data set and a back-end key; label: the table's name for it
  int pose_dof = 0;                  ///< for the ANEES interval of the average
  std::uint64_t seed = 0;
  RunScores scores;
  std::vector<std::pair<std::string, double>> extras;  ///< a study's own numbers (e.g. association precision)
  std::string failure;  ///< non-empty: the run failed as a whole with this message, scores are empty

  double extra(const std::string& name) const {
    for (const auto& [key, value] : extras)
      if (key == name) return value;
    return std::numeric_limits<double>::quiet_NaN();
  }
};

/// The most runs a study's record file may announce (ten million).
inline constexpr int kMaxStudyRuns = 10000000;

/// The file name of a shard's records: records-i-of-K.tsv.
inline std::string record_file_name(const Shard& shard) {
  return "records-" + std::to_string(shard.index) + "-of-" + std::to_string(shard.count) + ".tsv";
}

namespace detail {

inline constexpr const char* kRecordsMagic = "# sextant run records 2";
inline constexpr const char* kRecordColumns =
    "dataset\tcell\tlabel\tpose_dof\tseed\tsteps\tpose_mae\tpose_rmse\tpose_rmse_aligned\tpose_mae_aligned\tmap_mae\t"
    "map_mae_over_time\tmap_mae_aligned\tpose_nees_inside\tmap_nees_inside\tpose_anees\tpose_undersampled\t"
    "pose_anees_supported\ttotal_seconds\tfailed_steps\tfirst_failure\tfailure\textras";
inline constexpr std::size_t kRecordFields = 23;

/// A double as text that reads back to the same double (17 significant digits; nan, inf, -inf).
inline std::string exact(double x) {
  char text[40];
  std::snprintf(text, sizeof text, "%.17g", x);
  return text;
}

/// A string with backslash, tab and newline escaped, so that it stays one field of one line.
inline std::string escaped(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '\\') out += "\\\\";
    else if (c == '\t') out += "\\t";
    else if (c == '\n') out += "\\n";
    else if (c == '\r') out += "\\r";
    else out += c;
  }
  return out;
}

inline std::vector<std::pair<double RunScores::*, const char*>> score_fields() {
  return {{&RunScores::pose_mae, "pose_mae"},
          {&RunScores::pose_rmse, "pose_rmse"},
          {&RunScores::pose_rmse_aligned, "pose_rmse_aligned"},
          {&RunScores::pose_mae_aligned, "pose_mae_aligned"},
          {&RunScores::map_mae, "map_mae"},
          {&RunScores::map_mae_over_time, "map_mae_over_time"},
          {&RunScores::map_mae_aligned, "map_mae_aligned"},
          {&RunScores::pose_nees_inside, "pose_nees_inside"},
          {&RunScores::map_nees_inside, "map_nees_inside"},
          {&RunScores::pose_anees, "pose_anees"},
          {&RunScores::pose_undersampled, "pose_undersampled"},
          {&RunScores::pose_anees_supported, "pose_anees_supported"},
          {&RunScores::total_seconds, "total_seconds"}};
}

/// Reads one record file's lines, naming the file and line of the first problem.
class RecordParser {
 public:
  explicit RecordParser(std::string name) : name_(std::move(name)) {}

  [[noreturn]] void fail(const std::string& what) const {
    throw parse_error(name_ + ":" + std::to_string(line_) + ": " + what);
  }

  bool next(std::istream& in, std::string& text) {
    if (!std::getline(in, text)) return false;
    ++line_;
    if (!text.empty() && text.back() == '\r') text.pop_back();
    return true;
  }

  std::vector<std::string> fields(const std::string& text) const {
    std::vector<std::string> out(1);
    for (char c : text) {
      if (c == '\t') out.emplace_back();
      else out.back() += c;
    }
    return out;
  }

  std::string unescaped(const std::string& s) const {
    std::string out;
    for (std::size_t i = 0; i < s.size(); ++i) {
      if (s[i] != '\\') {
        out += s[i];
        continue;
      }
      if (++i == s.size()) fail("a field ends in a lone backslash");
      const char c = s[i];
      if (c == '\\') out += '\\';
      else if (c == 't') out += '\t';
      else if (c == 'n') out += '\n';
      else if (c == 'r') out += '\r';
      else fail(std::string("unknown escape \\") + c);
    }
    return out;
  }

  double number(const std::string& token, const char* column) const {
    if (token.empty()) fail(std::string(column) + ": empty, expected a number");
    char* end = nullptr;
    const double value = std::strtod(token.c_str(), &end);
    if (end != token.c_str() + token.size()) fail(std::string(column) + ": '" + token + "' is not a number");
    return value;
  }

  template <class Integer>
  Integer whole(const std::string& token, const char* column) const {
    Integer value{};
    const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
    if (ec != std::errc{} || end != token.data() + token.size() || token.empty())
      fail(std::string(column) + ": '" + token + "' is not a non-negative whole number");
    return value;
  }

  /// "key<TAB>value" with the expected key.
  std::string keyed(std::istream& in, const char* key) {
    std::string text;
    if (!next(in, text)) fail(std::string("truncated: the header ends before '") + key + "'");
    const auto f = fields(text);
    if (f.size() != 2 || f[0] != key) fail(std::string("expected the header line '") + key + "<TAB>value'");
    return unescaped(f[1]);
  }

  std::vector<std::pair<std::string, double>> extras(const std::string& token) const {
    std::vector<std::pair<std::string, double>> out;
    if (token.empty()) return out;
    std::stringstream list(token);
    for (std::string item; std::getline(list, item, ',');) {
      const auto eq = item.find('=');
      if (eq == std::string::npos || eq == 0) fail("extras: '" + item + "' is not name=value");
      out.emplace_back(item.substr(0, eq), number(item.substr(eq + 1), "extras"));
    }
    return out;
  }

  StudyRecord record(const std::vector<std::string>& f) const {
    if (f.size() != kRecordFields)
      fail("expected " + std::to_string(kRecordFields) + " tab-separated fields, found " + std::to_string(f.size()));
    StudyRecord r;
    r.dataset = unescaped(f[0]);
    r.cell = unescaped(f[1]);
    r.label = unescaped(f[2]);
    r.pose_dof = whole<int>(f[3], "pose_dof");
    if (r.pose_dof < 1 || r.pose_dof > 64) fail("pose_dof: " + f[3] + " is outside 1..64");
    r.seed = whole<std::uint64_t>(f[4], "seed");
    r.scores.steps = whole<std::size_t>(f[5], "steps");
    std::size_t column = 6;
    for (const auto& [field, name] : score_fields()) r.scores.*field = number(f[column++], name);
    r.scores.failed_steps = whole<std::size_t>(f[column++], "failed_steps");
    r.scores.first_failure = unescaped(f[column++]);
    r.failure = unescaped(f[column++]);
    r.extras = extras(f[column]);
    return r;
  }

  int line() const { return line_; }

 private:
  std::string name_;
  int line_ = 0;
};

}  // namespace detail

/// Writes `records` with their header: a magic line, program, study, runs, first_seed, shard, the
/// column names, a line per record and "end<TAB>count" (its absence marks a truncated file).
inline void write_records(std::ostream& out, const StudyHeader& h, const std::vector<StudyRecord>& records) {
  using detail::escaped, detail::exact;
  out << detail::kRecordsMagic << "\nprogram\t" << escaped(h.program) << "\nstudy\t" << escaped(h.study) << "\nruns\t"
      << h.runs << "\nfirst_seed\t" << h.first_seed << "\nshard\t" << to_string(h.shard) << "\n"
      << detail::kRecordColumns << "\n";
  for (const auto& r : records) {
    out << escaped(r.dataset) << '\t' << escaped(r.cell) << '\t' << escaped(r.label) << '\t' << r.pose_dof << '\t'
        << r.seed << '\t' << r.scores.steps;
    for (const auto& [field, name] : detail::score_fields()) out << '\t' << exact(r.scores.*field);
    out << '\t' << r.scores.failed_steps << '\t' << escaped(r.scores.first_failure) << '\t' << escaped(r.failure) << '\t';
    for (std::size_t i = 0; i < r.extras.size(); ++i)
      out << (i ? "," : "") << r.extras[i].first << '=' << exact(r.extras[i].second);
    out << '\n';
  }
  out << "end\t" << records.size() << '\n';
}

/// A record file as read: where it came from, its header, its records.
struct RecordFile {
  std::string name;
  StudyHeader header;
  std::vector<StudyRecord> records;
};

/// Parses a record file's text (`name` for messages); parse_error names the line of a problem, and
/// a file without its end line is refused as truncated.
inline RecordFile parse_records(std::istream& in, const std::string& name) {
  detail::RecordParser p(name);
  RecordFile file{name, {}, {}};
  std::string text;
  if (!p.next(in, text) || text != detail::kRecordsMagic)
    p.fail(std::string("not a sextant record file (its first line is not '") + detail::kRecordsMagic + "')");
  auto& h = file.header;
  h.program = p.keyed(in, "program");
  h.study = p.keyed(in, "study");
  h.runs = p.whole<int>(p.keyed(in, "runs"), "runs");
  if (h.runs < 1 || h.runs > kMaxStudyRuns) p.fail("runs: " + std::to_string(h.runs) + " is outside 1.." + std::to_string(kMaxStudyRuns));
  h.first_seed = p.whole<std::uint64_t>(p.keyed(in, "first_seed"), "first_seed");
  if (h.first_seed > std::numeric_limits<std::uint64_t>::max() - static_cast<std::uint64_t>(h.runs))
    p.fail("first_seed: the study's seeds would pass 2^64");
  const auto shard = p.keyed(in, "shard");
  try {
    h.shard = parse_shard(shard);
  } catch (const invalid_input_error& e) {
    p.fail(e.what());
  }
  if (!p.next(in, text) || text != detail::kRecordColumns) p.fail("expected the column names of format 2");
  while (p.next(in, text)) {
    const auto f = p.fields(text);
    if (f.size() == 2 && f[0] == "end") {
      if (p.whole<std::size_t>(f[1], "end") != file.records.size())
        p.fail("the end line counts " + f[1] + " records, the file holds " + std::to_string(file.records.size()));
      if (p.next(in, text)) p.fail("text after the end line");
      return file;
    }
    file.records.push_back(p.record(f));
  }
  throw parse_error(name + ": truncated: no end line after " + std::to_string(file.records.size()) + " records");
}

inline RecordFile read_records(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw parse_error(path + ": cannot open the record file");
  return parse_records(in, path);
}

/// Writes `records` to dir/records-i-of-K.tsv (creating dir); returns the path.
inline std::string write_record_file(const std::string& dir, const StudyHeader& h, const std::vector<StudyRecord>& records) {
  std::filesystem::create_directories(dir);
  const auto path = (std::filesystem::path(dir) / record_file_name(h.shard)).string();
  std::ofstream out(path);
  write_records(out, h, records);
  if (!out.flush()) throw error("cannot write " + path);
  return path;
}

/// The record files a --merge argument names: the file itself, or every records-*-of-*.tsv in a
/// directory (none there is an error).
inline std::vector<std::string> record_files_in(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::is_directory(path, ec)) {
    if (!fs::exists(path, ec)) throw parse_error(path + ": no such record file or directory");
    return {path};
  }
  std::vector<std::string> files;
  for (const auto& entry : fs::directory_iterator(path)) {
    const auto name = entry.path().filename().string();
    if (name.starts_with("records-") && name.ends_with(".tsv")) files.push_back(entry.path().string());
  }
  if (files.empty()) throw parse_error(path + ": holds no record file (records-i-of-K.tsv)");
  std::sort(files.begin(), files.end());
  return files;
}

namespace detail {

/// "a..b, c" for the seeds of `range` not in `present` (a subset of it), in time linear in `present`.
inline std::string missing_seeds(const SeedRange& range, const std::set<std::uint64_t>& present) {
  std::string out;
  const auto add_gap = [&](std::uint64_t from, std::uint64_t to) {  // seeds [from, to)
    if (from < to) out += (out.empty() ? "" : ", ") + to_string(SeedRange{from, static_cast<int>(to - from)});
  };
  std::uint64_t next = range.first;
  for (const std::uint64_t seed : present) {
    add_gap(next, seed);
    next = seed + 1;
  }
  add_gap(next, range.first + static_cast<std::uint64_t>(range.count));
  return out;
}

inline void require_same_study(const RecordFile& first, const RecordFile& f) {
  const auto differs = [&](const char* what, const std::string& a, const std::string& b) {
    if (a != b)
      throw invalid_input_error(f.name + ": another study than " + first.name + " (" + what + " '" + b + "' against '" +
                                a + "'): only shards of one study merge");
  };
  differs("program", first.header.program, f.header.program);
  differs("study", first.header.study, f.header.study);
  differs("runs", std::to_string(first.header.runs), std::to_string(f.header.runs));
  differs("first seed", std::to_string(first.header.first_seed), std::to_string(f.header.first_seed));
  differs("shard count", std::to_string(first.header.shard.count), std::to_string(f.header.shard.count));
}

/// The cells of a file, in the order they first appear.
inline std::vector<std::pair<std::string, std::string>> cells_of(const RecordFile& f) {
  std::vector<std::pair<std::string, std::string>> cells;
  for (const auto& r : f.records)
    if (std::find(cells.begin(), cells.end(), std::pair{r.dataset, r.cell}) == cells.end())
      cells.emplace_back(r.dataset, r.cell);
  return cells;
}

/// Every run of every cell of shard file `f`, once: throws naming the file and the missing seeds.
inline void require_complete_shard(const RecordFile& f, const std::vector<std::pair<std::string, std::string>>& cells) {
  const auto range = seeds_of(f.header.shard, f.header.runs, f.header.first_seed);
  std::map<std::pair<std::string, std::string>, std::set<std::uint64_t>> seeds;
  for (const auto& r : f.records) {
    const std::pair cell{r.dataset, r.cell};
    if (std::find(cells.begin(), cells.end(), cell) == cells.end())
      throw invalid_input_error(f.name + ": cell " + r.dataset + "/" + r.cell + " is in no other shard of the study");
    if (!range.contains(r.seed))
      throw invalid_input_error(f.name + ": seed " + std::to_string(r.seed) + " is not one of shard " +
                                to_string(f.header.shard) + " (seeds " + to_string(range) + ")");
    if (!seeds[cell].insert(r.seed).second)
      throw invalid_input_error(f.name + ": seed " + std::to_string(r.seed) + " of " + r.dataset + "/" + r.cell +
                                " twice");
  }
  for (const auto& cell : cells) {
    const auto missing = missing_seeds(range, seeds[cell]);
    if (!missing.empty())
      throw invalid_input_error(f.name + ": " + cell.first + "/" + cell.second + " lacks seeds " + missing +
                                " of shard " + to_string(f.header.shard));
  }
}

}  // namespace detail

/// The runs of every shard of one study, each cell's runs in seed order and the cells in the order
/// of the first shard's file that holds runs. Refuses files of different studies, a shard given twice, a missing shard
/// (naming its file name and seeds) and a shard that lacks runs (naming the file and seeds): nothing
/// is averaged over fewer runs than the study has.
inline std::vector<StudyRecord> merge_records(std::vector<RecordFile> files) {
  if (files.empty()) throw invalid_input_error("no record files to merge");
  std::sort(files.begin(), files.end(),
            [](const RecordFile& a, const RecordFile& b) { return a.header.shard.index < b.header.shard.index; });
  const auto& h = files.front().header;
  for (std::size_t i = 1; i < files.size(); ++i) {
    detail::require_same_study(files.front(), files[i]);
    if (files[i].header.shard.index == files[i - 1].header.shard.index)
      throw invalid_input_error(files[i].name + " and " + files[i - 1].name + " are both shard " +
                                to_string(files[i].header.shard));
  }
  std::string missing;
  int missing_count = 0;
  for (int index = 0, next = 0; index < h.shard.count; ++index) {
    if (next < static_cast<int>(files.size()) && files[next].header.shard.index == index) {
      ++next;
      continue;
    }
    const Shard shard{index, h.shard.count};
    if (seeds_of(shard, h.runs, h.first_seed).count == 0) continue;  // an empty shard may write no file
    if (++missing_count <= 5)
      missing += (missing.empty() ? "" : "; ") + record_file_name(shard) + " (seeds " +
                 to_string(seeds_of(shard, h.runs, h.first_seed)) + ")";
  }
  if (missing_count > 5) missing += "; and " + std::to_string(missing_count - 5) + " more";
  if (!missing.empty())
    throw invalid_input_error("the study of " + files.front().name + " misses shard files: " + missing);
  const auto holding = std::find_if(files.begin(), files.end(), [](const RecordFile& f) { return !f.records.empty(); });
  const auto cells = holding == files.end() ? decltype(detail::cells_of(files.front())){} : detail::cells_of(*holding);
  for (const auto& f : files) detail::require_complete_shard(f, cells);
  std::vector<StudyRecord> merged;
  for (const auto& cell : cells) {
    const auto begin = merged.size();
    for (const auto& f : files)
      for (const auto& r : f.records)
        if (r.dataset == cell.first && r.cell == cell.second) merged.push_back(r);
    std::sort(merged.begin() + static_cast<std::ptrdiff_t>(begin), merged.end(),
              [](const StudyRecord& a, const StudyRecord& b) { return a.seed < b.seed; });
  }
  return merged;
}

}  // namespace sextant::eval
