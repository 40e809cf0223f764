#pragma once
// The runner's data-set runs, each compiled in its own translation unit (the rawlog ones: rawlog_runs.hpp).
// Declarations only, so that the programs' main() units compile without the config and the table.
#include <string>
#include <vector>

#include "table_row.hpp"

namespace sextant::runner {

struct RunnerConfig;  // runner_config.hpp

/// Where and what to write besides the table.
struct RunOptions {
  std::string out;     ///< directory for per-run files; empty: none
  bool plots = false;  ///< also PNG plots
};

/// The simulated ship, config.ship_runs Monte Carlo runs (run_ship.cpp).
std::vector<TableRow> run_ship(const RunOptions& options, const std::vector<BackendKind>& kinds, const RunnerConfig& config);
/// A rawlog with its ground truth beside it, planar or spatial as the log is (run_planar_rawlog.cpp).
std::vector<TableRow> run_rawlog(const RunOptions& options, const std::string& path, const std::vector<BackendKind>& kinds,
                                 const RunnerConfig& config);
/// The simulated globe: the 12D camera, every back-end through the landmark pool (run_globe.cpp).
std::vector<TableRow> run_globe(const RunOptions& options, const std::vector<BackendKind>& kinds, const RunnerConfig& config);

/// One or all robots of a UTIAS MRCLAM data set, spec "<directory>:<robot 1-5 | all>" (run_mrclam.cpp).
std::vector<TableRow> run_mrclam(const RunOptions& options, const std::string& spec, const std::vector<BackendKind>& kinds,
                                 const RunnerConfig& config);
/// A planar data set in the iSAM/GTSAM text format, scored if its ground truth lies beside it (run_isam.cpp).
std::vector<TableRow> run_isam(const RunOptions& options, const std::string& path, const std::vector<BackendKind>& kinds,
                               const RunnerConfig& config);

}  // namespace sextant::runner
