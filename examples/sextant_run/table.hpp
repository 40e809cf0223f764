#pragma once
// The comparison table: the names of back-ends with their settings, printing the rows and writing
// them as JSON. Light: no back-end is instantiated here.
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iomanip>
#include <limits>
#include <optional>
#include <sextant/eval/experiment.hpp>
#include <sextant/io/implausible_values.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "runner_config.hpp"
#include "table_row.hpp"

namespace sextant::runner {

/// SEIF's name in the table: ESEIF-SLAM when it relocalizes (Walter, Eustice and Leonard's exactly
/// sparse filter), with its active-set size (0 = all).
inline std::string seif_label(bool relocalizing, std::size_t max_active) {
  return std::string(relocalizing ? "ESEIF-SLAM, " : "SEIF-SLAM, ") + (max_active ? std::to_string(max_active) : "all") +
         " active";
}

/// The table's name of a back-end with its main setting.
inline std::string backend_label(BackendKind kind, const RunnerConfig& c) {
  switch (kind) {
    case BackendKind::ekf: return "EKF-SLAM";
    case BackendKind::seif:
    case BackendKind::eseif:
      return seif_label(kind == BackendKind::eseif || c.seif.sparsification == SeifSparsification::relocalization,
                        c.seif.max_active);
    case BackendKind::graph: return "GraphSLAM";
    case BackendKind::fastslam1:
    case BackendKind::fastslam2:
      return std::string(kind == BackendKind::fastslam1 ? "FastSLAM 1.0, " : "FastSLAM 2.0, ") +
             std::to_string(c.fastslam.particles) + (c.fastslam.keep_paths ? " part., path" : " particles");
  }
  return "?";
}

/// The table's header line; the README's results table must show the same (tests/mrpt/runner_cli_test).
inline void print_header() {
  std::printf("%-29s %10s %10s %10s %10s %13s %12s %11s %10s %13s\n", "back-end", "pose MAE", "aligned", "map MAE",
              "aligned", "pose NEES in", "map NEES in", "pose ANEES", "total [s]", "per step[us]");
}

/// A score as the table prints it: "-" when there is none (no ground truth).
inline std::string cell(const char* format, double value) {
  if (std::isnan(value)) return "-";
  char text[32];
  std::snprintf(text, sizeof text, format, value);
  return text;
}

/// The reader's warnings about implausible values, one line each (io::ImplausibleValues).
inline void print_warnings(const io::ImplausibleValues& implausible) {
  for (const auto& line : implausible.warnings()) std::printf("%s\n", line.c_str());
}

/// The line below a row whose steps (or frames) failed and were skipped (eval::StepErrors::skip),
/// indented by `indent` characters; nothing for none. Every family's table prints it.
inline void print_skipped_steps(int indent, std::size_t count, const char* unit, const std::string& first) {
  if (count == 0) return;
  std::printf("%-*s %zu failed %s%s skipped (the back-end kept its state); first: %s\n", indent, "", count, unit,
              count == 1 ? "" : "s", first.c_str());
}

/// The line below an ESEIF row: how often it relocalized, how many landmarks stay linked to the robot;
/// below any SEIF row that recovered its whole mean for staleness ([seif] stale_mean_probability), how often.
inline void print_relocalization(int indent, const RelocalizationRow& r) {
  if (r.relocalizes)
    std::printf("%-*s relocalized at %.0f of %.0f steps; %.0f landmarks linked to the robot at the end (at most %.0f%s)\n",
                indent, "", r.relocalizations, r.steps, r.active, r.max_active,
                r.active > r.max_active ? " when that many of a step's landmarks carry enough information about the robot" : "");
  if (r.stale_recoveries > 0.0)
    std::printf("%-*s the whole mean recovered exactly at %.0f of %.0f steps, where the map beside the active block "
                "lagged (stale_mean_probability)\n",
                indent, "", r.stale_recoveries, r.steps);
}

/// " in k of n runs" where a row has more than one run.
inline std::string in_runs(int k, int runs) {
  return runs > 1 ? " in " + std::to_string(k) + " of " + std::to_string(runs) + " runs" : std::string();
}

/// The lines below a GraphSLAM row whose final optimization (Gauss-Newton or Levenberg-Marquardt)
/// stopped at its iteration limit before converging in some run (its estimate is then not the
/// optimum the row's scores are meant to show), went on damped after Gauss-Newton's cost rose (a start
/// far from the optimum), or, with that off, kept an earlier iterate than its last.
inline void print_optimization(int indent, const OptimizationRow& o) {
  if (o.unconverged > 0)
    std::printf("%-*s optimization stopped at its limit of %d iteration%s before converging%s; [graph] max_iterations "
                "raises it\n", indent, "", o.iterations, o.iterations == 1 ? "" : "s", in_runs(o.unconverged, o.runs).c_str());
  if (o.kept_earlier > 0) {
    const std::string where = o.kept_iteration == 0 ? std::string("at its start, which it kept")
                                                    : "at iteration " + std::to_string(o.kept_iteration) + ", whose estimate it kept";
    std::printf("%-*s Gauss-Newton's cost was lowest %s, higher in the %d iteration%s after it%s; [graph] "
                "damp_after_rise = true descends\n", indent, "", where.c_str(), o.kept_of - o.kept_iteration,
                o.kept_of - o.kept_iteration == 1 ? "" : "s",
                o.runs > 1 ? (in_runs(o.kept_earlier, o.runs) + ", the first of them shown").c_str() : "");
  }
  if (o.damped > 0)
    std::printf("%-*s Gauss-Newton's cost rose at iteration %d%s: that step was undone and the steps after it damped "
                "(Levenberg-Marquardt)\n", indent, "", o.damped_from,
                o.runs > 1 ? (in_runs(o.damped, o.runs) + ", the first of them shown").c_str() : "");
}

/// The pose ANEES, or "collapsed" where some steps' covariance rests on too few particles to be one
/// (eval::RunScores::pose_undersampled): a particle cloud's NEES there is 1e5-1e8, the sample's size.
inline std::string anees_cell(const eval::Summary& s) {
  return s.pose_undersampled > 0.0 ? std::string("collapsed") : cell("%.4g", s.pose_anees);
}

inline void print_row(const TableRow& row) {
  if (row.failure) {
    std::printf("%-29s failed: %s\n", row.label.c_str(), row.failure->c_str());
    return;
  }
  const auto& s = row.summary;
  std::printf("%-29s %10s %10s %10s %10s %13s %12s %11s %10.4f %13.1f\n", row.label.c_str(), cell("%.4g", s.pose_mae).c_str(),
              cell("%.4g", s.pose_mae_aligned).c_str(), cell("%.4g", s.map_mae).c_str(), cell("%.4g", s.map_mae_aligned).c_str(),
              cell("%.1f%%", 100.0 * s.pose_nees_inside).c_str(), cell("%.1f%%", 100.0 * s.map_nees_inside).c_str(),
              anees_cell(s).c_str(), s.total_seconds, 1e6 * s.seconds_per_step);
  if (const auto& a = row.association)
    std::printf("%-29s association: precision %.4f, recall %.4f; %zu wrong pairings, %zu duplicate landmarks, %zu "
                "discarded%s\n", "", a->precision, a->recall, a->wrong, a->duplicates, a->discarded,
                a->searches_cut == 0 ? "" : ("; JCBB cut at its node limit at " + std::to_string(a->searches_cut) + " steps").c_str());
  if (const auto& cloud = row.cloud)
    std::printf("%-29s the cloud at the end: N_eff %.3g of %.0f; all descend from %.0f of the %.0f it started with\n", "",
                cloud->effective_sample_size, cloud->particles, cloud->distinct_ancestors, cloud->particles);
  if (s.pose_undersampled > 0.0)
    std::printf("%-29s collapsed: at %.1f%% of the steps the pose rests on fewer than dof + 1 effective particles, "
                "its NEES there the sample's; the ANEES over the other steps: %s\n", "", 100.0 * s.pose_undersampled,
                cell("%.4g", s.pose_anees_supported).c_str());
  if (const auto& r = row.relocalization) print_relocalization(29, *r);
  if (const auto& o = row.optimization) print_optimization(29, *o);
  print_skipped_steps(29, row.summary.failed_steps, "step", row.summary.first_failure);  // over all its runs
}

inline std::string json_number(double x) {
  if (!std::isfinite(x)) return "null";
  std::ostringstream out;
  out << std::setprecision(10) << x;
  return out.str();
}

/// `text` as the inside of a JSON string.
inline std::string json_escaped(const std::string& text) {
  std::string out;
  for (unsigned char ch : text) {
    if (ch == '"' || ch == '\\') {
      out += '\\';
      out += static_cast<char>(ch);
    } else if (ch < 0x20) {
      char escaped[8];
      std::snprintf(escaped, sizeof escaped, "\\u%04x", ch);
      out += escaped;
    } else {
      out += static_cast<char>(ch);
    }
  }
  return out;
}

/// The table as JSON: one object per row.
inline void write_summary_json(const std::string& path, const std::vector<TableRow>& rows) {
  std::ofstream out(path);
  if (!out) throw error("cannot open " + path + " for writing");
  out << std::setprecision(10) << "[\n";
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const auto& s = rows[i].summary;
    out << "  {\"dataset\": \"" << json_escaped(rows[i].dataset) << "\", \"backend\": \"" << rows[i].backend
        << "\", \"label\": \"" << json_escaped(rows[i].label) << "\", \"runs\": " << rows[i].runs << ", \"pose_mae\": " << json_number(s.pose_mae)
        << ", \"map_mae\": " << json_number(s.map_mae) << ", \"pose_mae_aligned\": " << json_number(s.pose_mae_aligned)
        << ", \"pose_rmse\": " << json_number(s.pose_rmse) << ", \"pose_rmse_aligned\": " << json_number(s.pose_rmse_aligned)
        << ", \"map_mae_aligned\": " << json_number(s.map_mae_aligned) << ", \"pose_nees_inside\": " << json_number(s.pose_nees_inside)
        << ", \"map_nees_inside\": " << json_number(s.map_nees_inside) << ", \"pose_anees\": " << json_number(s.pose_anees)
        << ", \"pose_undersampled\": " << json_number(s.pose_undersampled)
        << ", \"pose_anees_supported\": " << json_number(s.pose_anees_supported)
        << ", \"total_seconds\": " << json_number(s.total_seconds)
        << ", \"seconds_per_step\": " << json_number(s.seconds_per_step) << ", \"failed_steps\": " << s.failed_steps;
    if (const auto& f = rows[i].failure) out << ", \"failure\": \"" << json_escaped(*f) << "\"";
    if (const auto& a = rows[i].association)
      out << ", \"association_precision\": " << json_number(a->precision)
          << ", \"association_recall\": " << json_number(a->recall);
    if (const auto& r = rows[i].relocalization) {
      if (r->relocalizes)
        out << ", \"relocalizations\": " << json_number(r->relocalizations) << ", \"active_at_end\": " << json_number(r->active);
      if (r->stale_recoveries >= 0.0) out << ", \"stale_recoveries\": " << json_number(r->stale_recoveries);
    }
    if (const auto& o = rows[i].optimization)
      out << ", \"optimization_unconverged_runs\": " << o->unconverged << ", \"optimization_earlier_iterate_runs\": " << o->kept_earlier
          << ", \"optimization_damped_runs\": " << o->damped;
    out << "}" << (i + 1 < rows.size() ? ",\n" : "\n");
  }
  out << "]\n";
}

}  // namespace sextant::runner
