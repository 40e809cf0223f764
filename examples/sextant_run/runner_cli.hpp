#pragma once
// The command line that sextant-run and the programs it hands data sets over to share: options,
// back-end names, the legend and summary.json after the table, one-line errors. Declarations only:
// runner_cli.cpp is compiled once for all of them (docs/build_times.md); the data-set families are
// in dataset_registry.hpp.
#include <functional>
#include <string>
#include <vector>

#include "dataset_runs.hpp"
#include "monte_carlo_study.hpp"

namespace sextant::runner {

struct CliOptions {
  std::vector<std::string> backends{"all"};
  std::vector<std::string> datasets;
  std::string config;
  int runs = 0;
  std::string associate;  ///< overrides [association] method when set
  bool print_config = false;
  std::string save_images;  ///< globe-stereo: write the rendered sequence here
  RunOptions output;
  std::string shard;               ///< --shard i/K: run only that share of the Monte Carlo seeds
  std::vector<std::string> merge;  ///< --merge: record files or directories of one study to print the table of
  StudyPart study;                 ///< this process's part in Monte Carlo studies (program_main sets it)
};

std::vector<BackendKind> parse_backends(const std::vector<std::string>& names);

/// The config file with the command line's overrides applied.
RunnerConfig load_runner_config(CliOptions& options);

/// What follows the table: the legend of its columns and, with --out, summary.json.
void finish_run(const CliOptions& options, const std::vector<TableRow>& rows);

/// Every program's main: parse the options, answer --print-config, then `run(options)`; an error is
/// one line on stderr, naming the program, and exit code 1.
int runner_main(int argc, char** argv, const char* program, const std::string& description,
                const std::function<int(CliOptions&)>& run);

/// One data set of a family (`dataset` as --dataset gave it): its rows of the table.
using DatasetRun = std::vector<TableRow> (*)(const CliOptions& options, const std::string& dataset,
                                             const std::vector<BackendKind>& kinds, const RunnerConfig& config);

}  // namespace sextant::runner
