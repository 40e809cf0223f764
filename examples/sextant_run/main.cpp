// sextant-run: every back-end on the simulated ship and on MRPT rawlogs, scored against ground
// truth, side by side; and the thesis's 12D camera around a simulated globe (--dataset globe). With no arguments: all back-ends on the ship Monte Carlo and on the kf-slam
// demo rawlogs that Debian's mrpt-common installs. See docs/runner.md.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <variant>
#include <vector>

#include "dataset_runs.hpp"
#include "runner_config.hpp"
#include "table.hpp"

namespace {

using namespace sextant;
using namespace sextant::runner;

const char* const kMrptDatasets = "/usr/share/mrpt/datasets";
const std::vector<std::string> kMrptDemos = {"kf-slam_demo.rawlog", "kf-slam_6D_demo.rawlog",
                                             "kf-slam_6D_demo_noncentered.rawlog"};

struct Options {
  std::vector<std::string> backends{"all"};
  std::vector<std::string> datasets;
  std::string config;
  int runs = 0;
  RunOptions output;
};

std::vector<BackendKind> parse_backends(const std::vector<std::string>& names) {
  std::vector<BackendKind> kinds;
  for (const auto& name : names) {
    if (name == "all") return all_backends();
    const auto it = std::find_if(all_backends().begin(), all_backends().end(),
                                 [&](BackendKind k) { return backend_key(k) == name; });
    if (it == all_backends().end())
      throw invalid_input_error("--backend: unknown back-end '" + name + "' (ekf|seif|graph|fastslam1|fastslam2|all)");
    if (std::find(kinds.begin(), kinds.end(), *it) == kinds.end()) kinds.push_back(*it);
  }
  return kinds;
}

/// "ship", "mrpt-demos" (the installed demo rawlogs) or a rawlog path, expanded.
std::vector<std::string> expand_datasets(const std::vector<std::string>& requested) {
  std::vector<std::string> out;
  for (const auto& d : requested.empty() ? std::vector<std::string>{"ship", "mrpt-demos"} : requested) {
    if (d != "mrpt-demos") {
      out.push_back(d);
      continue;
    }
    for (const auto& demo : kMrptDemos) {
      const auto path = std::string(kMrptDatasets) + "/" + demo;
      if (std::filesystem::exists(path)) out.push_back(path);
      else std::printf("note: %s not found (Debian package mrpt-common), skipped\n", path.c_str());
    }
  }
  return out;
}

/// The ground-truth files beside a rawlog, which sextant-run needs to score the runs.
mrpt_io::GroundTruthFiles require_ground_truth(const std::string& path) {
  const auto truth = mrpt_io::find_ground_truth(path);
  if (!truth)
    throw parse_error(path + ": no ground truth beside it (<name>_ground_truth.txt and "
                             "<name>_ground_truth_robot_path.txt); sextant-run scores against ground truth");
  return *truth;
}

/// A rawlog with the MRPT ground-truth files beside it, as planar or spatial.
std::vector<TableRow> run_rawlog(const Options& options, const std::string& path, const std::vector<BackendKind>& kinds,
                                 const RunnerConfig& config) {
  const std::string name = std::filesystem::path(path).filename().string();
  auto dataset = mrpt_io::read_rawlog(path, config.rawlog);
  return std::visit(
      [&](auto& data) {
        mrpt_io::attach_ground_truth(data, require_ground_truth(path));
        return run_rawlog_dataset(options.output, name, data, kinds, config);
      },
      dataset);
}

std::string one_line(const std::string& text) {
  std::string line = text.substr(0, text.find('\n'));
  return line.empty() ? "unknown error" : line;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"sextant-run: SLAM back-ends on the simulated ship and on MRPT rawlogs, side by side"};
  Options options;
  bool print_config = false;
  app.add_option("--backend,-b", options.backends, "ekf|seif|graph|fastslam1|fastslam2|all (repeatable)")
      ->delimiter(',')
      ->capture_default_str();
  app.add_option("--dataset,-d", options.datasets,
                 "ship | globe | mrpt-demos | <file.rawlog> (repeatable; default: ship and the MRPT kf-slam demos)");
  app.add_option("--config,-c", options.config, "ini file (MRPT CConfigFile) with [ship] [globe] [rawlog] [ekf] [seif] [graph] "
                                                "[fastslam] [scene] keys; see --print-config");
  app.add_option("--out,-o", options.output.out, "directory for per-step CSV, TUM, .3Dscene files and summary.json");
  app.add_option("--runs", options.runs, "Monte Carlo runs on the ship (overrides [ship] runs)")->check(CLI::Range(1, 100000));
  app.add_flag("--plots", options.output.plots, "also write PNG plots of trajectory, map, error and NEES (needs --out or "
                                         "writes to ./sextant-run-output)");
  app.add_flag("--print-config", print_config, "print every config key with its default and meaning, then exit");
  CLI11_PARSE(app, argc, argv);

  if (print_config) {
    std::fputs(documented_defaults().c_str(), stdout);
    return 0;
  }
  try {
    RunnerConfig config = load_config(options.config);
    if (options.runs > 0) config.ship_runs = options.runs;
    if (options.output.plots && options.output.out.empty()) options.output.out = "sextant-run-output";
    const auto kinds = parse_backends(options.backends);
    std::vector<TableRow> rows;
    for (const auto& dataset : expand_datasets(options.datasets)) {
      auto part = dataset == "ship"    ? run_ship(options.output, kinds, config)
                  : dataset == "globe" ? run_globe(options.output, kinds, config)
                                       : run_rawlog(options, dataset, kinds, config);
      rows.insert(rows.end(), part.begin(), part.end());
    }
    std::printf("\naligned: the same error after the best rigid alignment of the trajectory (map) to the truth; "
                "NEES in: share of steps (pose) or landmarks (map) whose NEES is inside the 95%% chi-square bound; "
                "pose ANEES: mean NEES over steps and runs (pose dof: ship 2, planar 3, 6D 6).\n");
    if (!options.output.out.empty()) {
      std::filesystem::create_directories(options.output.out);
      const auto json = (std::filesystem::path(options.output.out) / "summary.json").string();
      write_summary_json(json, rows);
      std::printf("wrote %s\n", json.c_str());
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "sextant-run: %s\n", one_line(e.what()).c_str());
    return 1;
  }
  return 0;
}
