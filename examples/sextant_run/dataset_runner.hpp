#pragma once
// What one data set's part of the run does, for any data set type: run the chosen back-ends, print
// their rows, write their files. Included by the translation units that instantiate it, one per
// data-set family (run_ship.cpp, run_planar_rawlog.cpp, run_spatial_rawlog.cpp), which a build on
// several cores compiles side by side.
#include <filesystem>
#include <string>
#include <vector>

#include "dataset_runs.hpp"
#include "experiments.hpp"
#include "plot_script.hpp"
#include "run_outputs.hpp"

namespace sextant::runner {

inline std::string directory_name(const std::string& dataset) {
  return dataset == "ship" ? "ship" : std::filesystem::path(dataset).stem().string();
}

/// Writes the files of every run of one data set and, if asked, the plots.
template <class Dataset>
void write_dataset_outputs(const RunOptions& options, const std::string& dataset, const Dataset& data,
                           const std::vector<std::pair<BackendKind, BackendRun<Dataset>>>& runs,
                           const RunnerConfig& config, const char* unit) {
  if (options.out.empty()) return;
  const auto dir = std::filesystem::path(options.out) / directory_name(dataset);
  for (const auto& [kind, run] : runs) write_run_outputs(dir, kind, run, data, config);
  std::printf("wrote per-step CSV, map CSV, TUM trajectories and .3Dscene files to %s\n", dir.c_str());
  if (!options.plots) return;
  run_plot_script("plot_run.py", dir, unit);
}

/// The title and column header of one data set's part of the table.
template <class Dataset>
void print_dataset_header(const std::string& name, const Dataset& data, const char* unit) {
  std::printf("\n== %s: %zu steps, %zu landmarks in the ground truth; errors in %s\n", name.c_str(), data.steps.size(),
              data.true_landmarks.size(), unit);
  print_header();
}

/// Runs the chosen back-ends on one data set, prints their rows, writes their outputs.
template <class Dataset>
std::vector<TableRow> run_dataset_rows(const RunOptions& options, const std::string& name, const Dataset& data,
                                       const std::vector<BackendKind>& kinds, const RunnerConfig& config,
                                       const char* unit) {
  if (kinds.empty()) return {};
  std::vector<std::pair<BackendKind, BackendRun<Dataset>>> runs;
  auto rows = run_on_rawlog(name, data, kinds, config, runs);
  for (const auto& row : rows) print_row(row);
  write_dataset_outputs(options, name, data, runs, config, unit);
  return rows;
}

/// Runs the chosen back-ends on one data set, prints its part of the table, writes its outputs.
template <class Dataset>
std::vector<TableRow> run_dataset(const RunOptions& options, const std::string& name, const Dataset& data,
                                  const std::vector<BackendKind>& kinds, const RunnerConfig& config,
                                  const char* unit) {
  print_warnings(data.implausible);
  print_dataset_header(name, data, unit);
  return run_dataset_rows(options, name, data, kinds, config, unit);
}

}  // namespace sextant::runner
