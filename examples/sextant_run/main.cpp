// sextant-run: every back-end on the simulated ship and on MRPT rawlogs, scored against ground
// truth, side by side. With no arguments: all back-ends on the ship Monte Carlo and on the kf-slam
// demo rawlogs that Debian's mrpt-common installs. See docs/runner.md.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <sextant/backends/ekf_slam.hpp>
#include <string>
#include <variant>
#include <vector>

#include "experiments.hpp"
#include "run_outputs.hpp"
#include "runner_config.hpp"

namespace {

using namespace sextant;
using namespace sextant::runner;

const char* const kMrptDatasets = "/usr/share/mrpt/datasets";
const std::vector<std::string> kMrptDemos = {"kf-slam_demo.rawlog", "kf-slam_6D_demo.rawlog",
                                             "kf-slam_6D_demo_noncentered.rawlog"};

struct Options {
  std::vector<std::string> backends{"all"};
  std::vector<std::string> datasets;
  std::string config, out;
  int runs = 0;
  bool plots = false;
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

void print_header() {
  std::printf("%-29s %11s %11s %14s %13s %11s %10s %13s\n", "back-end", "pose MAE", "map MAE", "pose NEES in", "map NEES in",
              "pose ANEES", "total [s]", "per step[us]");
}

void print_row(const TableRow& row) {
  const auto& s = row.summary;
  std::printf("%-29s %11.4g %11.4g %13.1f%% %12.1f%% %11.4g %10.4f %13.1f\n", row.label.c_str(), s.pose_mae, s.map_mae,
              100.0 * s.pose_nees_inside, 100.0 * s.map_nees_inside, s.pose_anees, s.total_seconds,
              1e6 * s.seconds_per_step);
}

std::string directory_name(const std::string& dataset) {
  return dataset == "ship" ? "ship" : std::filesystem::path(dataset).stem().string();
}

/// Writes the files of every run of one data set and, if asked, the plots.
template <class Dataset>
void write_dataset_outputs(const Options& options, const std::string& dataset, const Dataset& data,
                           const std::vector<std::pair<BackendKind, BackendRun<Dataset>>>& runs, const Scoring& scoring,
                           const RunnerConfig& config, const char* unit) {
  if (options.out.empty()) return;
  const auto dir = std::filesystem::path(options.out) / directory_name(dataset);
  for (const auto& [kind, run] : runs) write_run_outputs(dir, kind, run, data, scoring, config);
  std::printf("wrote per-step CSV, map CSV, TUM trajectories and .3Dscene files to %s\n", dir.c_str());
  if (!options.plots) return;
  const auto script = std::filesystem::canonical("/proc/self/exe").parent_path() / "plot_run.py";
  // Debian's interpreter (where python3-matplotlib installs) before whatever python3 is first on PATH.
  const std::string python = std::filesystem::exists("/usr/bin/python3") ? "/usr/bin/python3" : "python3";
  const std::string command = python + " '" + script.string() + "' '" + dir.string() + "' " + unit;
  if (std::system(command.c_str()) != 0)
    throw error(dir.string() + ": plotting failed (needs python3 with matplotlib: Debian python3-matplotlib)");
  std::printf("wrote plots (PNG) to %s\n", dir.c_str());
}

/// Runs the chosen back-ends on one data set, prints its part of the table, writes its outputs.
template <class Dataset>
std::vector<TableRow> run_dataset(const Options& options, const std::string& name, const Dataset& data,
                                  const std::vector<BackendKind>& kinds, const RunnerConfig& config,
                                  const Scoring& scoring, const char* unit) {
  std::printf("\n== %s: %zu steps, %zu landmarks in the ground truth; errors in %s\n", name.c_str(), data.steps.size(),
              data.true_landmarks.size(), unit);
  print_header();
  std::vector<std::pair<BackendKind, BackendRun<Dataset>>> runs;
  auto rows = run_on_rawlog(name, data, kinds, config, scoring, runs);
  for (const auto& row : rows) print_row(row);
  write_dataset_outputs(options, name, data, runs, scoring, config, unit);
  return rows;
}

std::vector<TableRow> run_ship(const Options& options, const std::vector<BackendKind>& kinds, const RunnerConfig& config) {
  const Scoring scoring{2, 2, 2};
  std::printf("\n== ship: the thesis's 2D beacon ship, %d steps, %d Monte Carlo run(s) from seed %llu; errors in km\n",
              config.ship.num_steps, config.ship_runs, static_cast<unsigned long long>(config.ship.seed));
  print_header();
  std::vector<std::pair<BackendKind, BackendRun<sim::Ship2DDataset>>> runs;
  auto rows = run_on_ship(kinds, config, scoring, runs);
  for (const auto& row : rows) print_row(row);
  write_dataset_outputs(options, "ship", sim::simulate_ship_2d(config.ship), runs, scoring, config, "km");
  return rows;
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
        constexpr bool planar = std::decay_t<decltype(data)>::Motion::kDim == 3;
        return run_dataset(options, name, data, kinds, config, planar ? Scoring{2, 3, 2} : Scoring{3, 6, 3}, "m");
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
                 "ship | mrpt-demos | <file.rawlog> (repeatable; default: ship and the MRPT kf-slam demos)");
  app.add_option("--config,-c", options.config, "ini file (MRPT CConfigFile) with [ship] [rawlog] [ekf] [seif] [graph] "
                                                "[fastslam] [scene] keys; see --print-config");
  app.add_option("--out,-o", options.out, "directory for per-step CSV, TUM, .3Dscene files and summary.json");
  app.add_option("--runs", options.runs, "Monte Carlo runs on the ship (overrides [ship] runs)")->check(CLI::Range(1, 100000));
  app.add_flag("--plots", options.plots, "also write PNG plots of trajectory, map, error and NEES (needs --out or "
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
    if (options.plots && options.out.empty()) options.out = "sextant-run-output";
    const auto kinds = parse_backends(options.backends);
    std::vector<TableRow> rows;
    for (const auto& dataset : expand_datasets(options.datasets)) {
      auto part = dataset == "ship" ? run_ship(options, kinds, config) : run_rawlog(options, dataset, kinds, config);
      rows.insert(rows.end(), part.begin(), part.end());
    }
    std::printf("\nNEES in: share of steps (pose) or landmarks (map) whose NEES is inside the 95%% chi-square bound; "
                "pose ANEES: mean NEES over steps and runs (pose dof: ship 2, planar 3, 6D 6).\n");
    if (!options.out.empty()) {
      std::filesystem::create_directories(options.out);
      const auto json = (std::filesystem::path(options.out) / "summary.json").string();
      write_summary_json(json, rows);
      std::printf("wrote %s\n", json.c_str());
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "sextant-run: %s\n", one_line(e.what()).c_str());
    return 1;
  }
  return 0;
}
