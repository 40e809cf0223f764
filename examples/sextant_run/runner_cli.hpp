#pragma once
// The command line that sextant-run and the programs it hands data sets over to share: options,
// back-end names, the legend and summary.json after the table, one-line errors. Declarations only:
// runner_cli.cpp is compiled once for all of them (docs/build_times.md).
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "dataset_runs.hpp"

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
};

/// A data set of sextant-globe: the simulated globe.
inline bool is_globe_dataset(const std::string& dataset) { return dataset == "globe"; }

/// A data set of sextant-vislam: the simulated stereo car or a .npz file.
inline bool is_vislam_dataset(const std::string& dataset) {
  return dataset == "stereo-vi" || std::filesystem::path(dataset).extension() == ".npz";
}

/// A data set of sextant-globe-stereo: the rendered globe or a stereo image directory.
inline bool is_stereo_image_dataset(const std::string& dataset) {
  return dataset == "globe-stereo" || dataset.rfind("stereo:", 0) == 0;
}

/// A data set of sextant-run-mrclam: "mrclam:<directory>:<robot 1-5 | all>".
inline bool is_mrclam_dataset(const std::string& dataset) { return dataset.rfind("mrclam:", 0) == 0; }

/// A data set of sextant-run-isam: a planar file in the iSAM/GTSAM text format, named .txt or .graph
/// (rawlogs are binary).
inline bool is_isam_dataset(const std::string& dataset) {
  const auto extension = std::filesystem::path(dataset).extension();
  return extension == ".txt" || extension == ".graph";
}

std::vector<BackendKind> parse_backends(const std::vector<std::string>& names);

/// The config file with the command line's overrides applied.
RunnerConfig load_runner_config(CliOptions& options);

/// What follows the table: the legend of its columns and, with --out, summary.json.
void finish_run(const CliOptions& options, const std::vector<TableRow>& rows);

/// Every program's main: parse the options, answer --print-config, then `run(options)`; an error is
/// one line on stderr, naming the program, and exit code 1.
int runner_main(int argc, char** argv, const char* program, const std::string& description,
                const std::function<int(CliOptions&)>& run);

/// One data set of a program's family: its rows of the table.
using DatasetRun = std::vector<TableRow> (*)(const CliOptions& options, const std::string& dataset,
                                             const std::vector<BackendKind>& kinds, const RunnerConfig& config);

/// Runs a family's data sets: every --dataset must be the family's (`is_its`; `what` names the
/// family in the message), none given means `defaults`, `expand` (if given) turns the list into the
/// data sets to run; each runs through `run_one`, then the legend. Returns main's exit code.
int run_datasets(CliOptions& options, const char* program, bool (*is_its)(const std::string&), const char* what,
                 DatasetRun run_one, const std::vector<std::string>& defaults = {},
                 std::vector<std::string> (*expand)(const std::vector<std::string>&) = nullptr);

/// main() of a program that runs one family of data sets alone (sextant-run hands them over to it,
/// so that the main job does not compile them): runner_main around run_datasets.
int family_main(int argc, char** argv, const char* program, const std::string& description,
                bool (*is_its)(const std::string&), const char* what, DatasetRun run_one,
                const std::vector<std::string>& defaults = {});

}  // namespace sextant::runner
