// The runner's table from a Monte Carlo study's records (monte_carlo_study.hpp), compiled once for
// every runner program.
#include "monte_carlo_study.hpp"

#include <algorithm>
#include <cstdio>

#include "table.hpp"

namespace sextant::runner {

std::vector<std::pair<std::string, double>> association_extras(const AssociationRow& a) {
  return {{"association_precision", a.precision},
          {"association_recall", a.recall},
          {"association_wrong", static_cast<double>(a.wrong)},
          {"association_duplicates", static_cast<double>(a.duplicates)},
          {"association_discarded", static_cast<double>(a.discarded)},
          {"association_searches_cut", static_cast<double>(a.searches_cut)}};
}

std::vector<std::pair<std::string, double>> cloud_extras(const CloudRow& cloud) {
  return {{"cloud_particles", cloud.particles},
          {"cloud_effective_sample_size", cloud.effective_sample_size},
          {"cloud_distinct_ancestors", cloud.distinct_ancestors}};
}

std::vector<std::pair<std::string, double>> relocalization_extras(const RelocalizationRow& r) {
  return {{"relocalization_steps", r.steps},
          {"relocalizations", r.relocalizations},
          {"relocalization_active", r.active},
          {"relocalization_max_active", r.max_active},
          {"relocalization_relocalizes", r.relocalizes ? 1.0 : 0.0},
          {"stale_recoveries", r.stale_recoveries}};
}

std::vector<std::pair<std::string, double>> optimization_extras(const OptimizationRow& o) {
  return {{"optimization_unconverged", static_cast<double>(o.unconverged)},
          {"optimization_iterations", static_cast<double>(o.iterations)},
          {"optimization_kept_earlier", static_cast<double>(o.kept_earlier)},
          {"optimization_kept_iteration", static_cast<double>(o.kept_iteration)},
          {"optimization_damped_from", static_cast<double>(o.damped_from)}};
}

namespace {

bool has_extra(const eval::StudyRecord& r, const char* name) {
  return std::any_of(r.extras.begin(), r.extras.end(), [&](const auto& e) { return e.first == name; });
}

/// An extra added after records were first written: `absent` in a record written before (extra()
/// would give NaN, which no count or iteration number may be cast from).
double extra_or(const eval::StudyRecord& r, const char* name, double absent) {
  return has_extra(r, name) ? r.extra(name) : absent;
}

std::optional<CloudRow> cloud_of(const eval::StudyRecord& r) {
  if (!has_extra(r, "cloud_particles")) return std::nullopt;
  return CloudRow{r.extra("cloud_particles"), r.extra("cloud_effective_sample_size"), r.extra("cloud_distinct_ancestors")};
}

std::optional<RelocalizationRow> relocalization_of(const eval::StudyRecord& r) {
  if (!has_extra(r, "relocalizations")) return std::nullopt;
  RelocalizationRow row{r.extra("relocalization_steps"), r.extra("relocalizations"), r.extra("relocalization_active"),
                        r.extra("relocalization_max_active")};
  if (has_extra(r, "relocalization_relocalizes")) row.relocalizes = r.extra("relocalization_relocalizes") != 0.0;
  if (has_extra(r, "stale_recoveries")) row.stale_recoveries = r.extra("stale_recoveries");
  return row;
}

std::optional<AssociationRow> association_of(const eval::StudyRecord& r) {
  if (!has_extra(r, "association_precision")) return std::nullopt;
  return AssociationRow{r.extra("association_precision"), r.extra("association_recall"), static_cast<std::size_t>(r.extra("association_wrong")),
                        static_cast<std::size_t>(r.extra("association_duplicates")),
                        static_cast<std::size_t>(r.extra("association_discarded")),
                        has_extra(r, "association_searches_cut") ? static_cast<std::size_t>(r.extra("association_searches_cut")) : 0};
}

/// In how many of records[begin, end) the final optimization stopped unconverged, in how many it
/// kept an earlier iterate than its last and in how many it went on damped; none for filters.
std::optional<OptimizationRow> optimization_of(std::vector<eval::StudyRecord>::const_iterator begin,
                                               std::vector<eval::StudyRecord>::const_iterator end) {
  if (!has_extra(*begin, "optimization_unconverged")) return std::nullopt;
  OptimizationRow row{.runs = static_cast<int>(end - begin)};
  for (auto r = begin; r != end; ++r) {
    const int iterations = static_cast<int>(r->extra("optimization_iterations"));
    if (r->extra("optimization_unconverged") != 0.0) {
      ++row.unconverged;
      row.iterations = std::max(row.iterations, iterations);
    }
    if (extra_or(*r, "optimization_kept_earlier", 0.0) != 0.0 && row.kept_earlier++ == 0) {
      row.kept_iteration = static_cast<int>(r->extra("optimization_kept_iteration"));
      row.kept_of = iterations;
    }
    const int damped_from = static_cast<int>(extra_or(*r, "optimization_damped_from", -1.0));
    if (damped_from >= 0 && row.damped++ == 0) row.damped_from = damped_from;
  }
  return row;
}

/// The row of one cell's runs (records[begin, end), in seed order).
TableRow row_of(std::vector<eval::StudyRecord>::const_iterator begin, std::vector<eval::StudyRecord>::const_iterator end) {
  TableRow row{.dataset = begin->dataset, .backend = begin->cell, .label = begin->label, .runs = static_cast<int>(end - begin)};
  std::vector<eval::RunScores> scores;
  for (auto r = begin; r != end; ++r) {
    if (!r->failure.empty() && !row.failure) row.failure = "seed " + std::to_string(r->seed) + ": " + r->failure;
    scores.push_back(r->scores);
  }
  if (row.failure) {
    row.summary.mark_unscored();
    return row;
  }
  row.summary = eval::summarize(scores, begin->pose_dof);
  row.association = association_of(*begin);  // the first seed's
  row.cloud = cloud_of(*begin);
  row.relocalization = relocalization_of(*begin);
  row.optimization = optimization_of(begin, end);
  return row;
}

}  // namespace

std::vector<TableRow> rows_of(const std::vector<eval::StudyRecord>& records) {
  std::vector<TableRow> rows;
  for (auto begin = records.begin(); begin != records.end();) {
    const auto end = std::find_if(begin, records.end(), [&](const eval::StudyRecord& r) {
      return r.dataset != begin->dataset || r.cell != begin->cell;
    });
    rows.push_back(row_of(begin, end));
    begin = end;
  }
  return rows;
}

std::vector<TableRow> merged_rows(const std::string& program, const std::vector<std::string>& paths) {
  eval::StudyHeader header;
  std::size_t count = 0;
  const auto rows = rows_of(merged_records(program, paths, header, count));
  std::string dataset;
  for (const auto& row : rows) {
    if (row.dataset != dataset) {
      dataset = row.dataset;
      std::printf("\n== %s: %d Monte Carlo run(s), seeds %s, merged from %zu record file(s) of %d shard(s)\n",
                  dataset.c_str(), header.runs, eval::to_string(eval::SeedRange{header.first_seed, header.runs}).c_str(),
                  count, header.shard.count);
      print_header();
    }
    print_row(row);
  }
  return rows;
}

}  // namespace sextant::runner
