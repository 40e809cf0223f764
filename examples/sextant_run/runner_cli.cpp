// The command line of sextant-run and the programs it hands data sets over to (runner_cli.hpp),
// compiled once for all of them.
#include "runner_cli.hpp"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <filesystem>

#include "dataset_registry.hpp"
#include "runner_config.hpp"
#include "table.hpp"

namespace sextant::runner {
namespace {

/// Declares the options every program takes.
void add_runner_options(CLI::App& app, CliOptions& options, const char* program) {
  app.add_option("--backend,-b", options.backends, "ekf|seif|eseif|graph|fastslam1|fastslam2|all (repeatable)")
      ->delimiter(',')
      ->capture_default_str();
  app.add_option("--dataset,-d", options.datasets, dataset_help(program));
  app.add_option("--config,-c", options.config, "ini file (MRPT CConfigFile) with [ship] [globe] [vislam] [rawlog] [ekf] [seif] [graph] "
                                                "[fastslam] [scene] keys; see --print-config");
  app.add_option("--out,-o", options.output.out, "directory for per-step CSV, TUM, .3Dscene files and summary.json");
  app.add_option("--associate", options.associate,
                 "known|nn|jcbb: use the data set's landmark ids, or withhold them and associate by nearest neighbour "
                 "or JCBB (EKF and SEIF; FastSLAM associates per particle; overrides [association] method)");
  app.add_option("--runs", options.runs, "Monte Carlo runs on the ship (overrides [ship] runs)")->check(CLI::Range(1, 100000));
  app.add_option("--shard", options.shard,
                 "i/K: run only shard i (from 0) of K of the Monte Carlo seeds and write their records to --out "
                 "(records-i-of-K.tsv) for --merge; under mpirun each rank takes its shard by itself");
  app.add_option("--merge", options.merge,
                 "record files or directories of one study's shards: print the table of the whole study (repeatable)");
  app.add_flag("--plots", options.output.plots, "also write PNG plots of trajectory, map, error and NEES (needs --out or "
                                                "writes to ./sextant-run-output)");
  app.add_option("--save-images", options.save_images,
                 "globe-stereo: also write the rendered stereo sequence to this directory (left/, right/, calib.yaml), "
                 "which --dataset stereo:<dir> reads back");
  app.add_flag("--print-config", options.print_config, "print every config key with its default and meaning, then exit");
}

std::string one_line(const std::string& text) {
  std::string line = text.substr(0, text.find('\n'));
  return line.empty() ? "unknown error" : line;
}

}  // namespace

std::vector<BackendKind> parse_backends(const std::vector<std::string>& names) {
  std::vector<BackendKind> kinds;
  for (const auto& name : names) {
    if (name == "all") return all_backends();
    const auto it = std::find_if(all_backends().begin(), all_backends().end(),
                                 [&](BackendKind k) { return backend_key(k) == name; });
    if (it == all_backends().end())
      throw invalid_input_error("--backend: unknown back-end '" + name + "' (ekf|seif|eseif|graph|fastslam1|fastslam2|all)");
    if (std::find(kinds.begin(), kinds.end(), *it) == kinds.end()) kinds.push_back(*it);
  }
  return kinds;
}

RunnerConfig load_runner_config(CliOptions& options) {
  RunnerConfig config = load_config(options.config);
  if (options.runs > 0) config.ship_runs = options.runs;
  if (!options.associate.empty()) {
    const auto key = std::find_if(config_keys().begin(), config_keys().end(),
                                  [](const ConfigKey& k) { return k.section == "association" && k.key == "method"; });
    try {
      key->apply(config, options.associate);
    } catch (const invalid_input_error& e) {
      throw invalid_input_error(std::string("--associate: ") + e.what());
    }
  }
  if (options.output.plots && options.output.out.empty()) options.output.out = "sextant-run-output";
  return config;
}

void finish_run(const CliOptions& options, const std::vector<TableRow>& rows) {
  std::printf("\naligned: the same error after the best rigid alignment of the trajectory (map) to the truth; "
              "NEES in: share of steps (pose) or landmarks (map) whose NEES is inside the 95%% chi-square bound; "
              "pose ANEES: mean NEES over steps and runs (pose dof: ship 2, planar 3, 6D 6), or 'collapsed' where a "
              "particle cloud's pose rested on fewer than dof + 1 effective particles.\n");
  if (options.output.out.empty()) return;
  std::filesystem::create_directories(options.output.out);
  const auto json = (std::filesystem::path(options.output.out) / "summary.json").string();
  write_summary_json(json, rows);
  std::printf("wrote %s\n", json.c_str());
}

int runner_main(int argc, char** argv, const char* program, const std::string& description,
                const std::function<int(CliOptions&)>& run) {
  CLI::App app{description};
  CliOptions options;
  add_runner_options(app, options, program);
  CLI11_PARSE(app, argc, argv);
  if (options.print_config) {
    std::fputs(documented_defaults().c_str(), stdout);
    return 0;
  }
  try {
    return run(options);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: %s\n", program, one_line(e.what()).c_str());
    return 1;
  }
}

}  // namespace sextant::runner
