// The thesis's 2D beacon-ship experiment (seed 000, §4.2.1, Tables 4 and 11): simulate, filter with
// every back-end, and print accuracy, consistency and time side by side; optionally write per-step
// CSV and TUM trajectories, and Monte Carlo ANEES over many seeds.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "sextant/backends/ekf_slam.hpp"
#include "sextant/backends/fast_slam.hpp"
#include "sextant/backends/graph_slam.hpp"
#include "sextant/backends/seif_slam.hpp"
#include "sextant/eval/experiment.hpp"
#include "sextant/eval/monte_carlo.hpp"
#include "sextant/io/csv_writer.hpp"
#include "sextant/io/tum_writer.hpp"
#include "sextant/models/beacon_ship_2d.hpp"
#include "sextant/sim/ship_2d.hpp"

namespace {

using namespace sextant;
using ShipEkf = EkfSlam<BeaconShip2D, BeaconOffset2D>;
using ShipSeif = SeifSlam<BeaconShip2D, BeaconOffset2D>;
using ShipGraph = GraphSlam<BeaconShip2D, BeaconOffset2D>;
using ShipFast = FastSlam<BeaconShip2D, BeaconOffset2D>;

using RunSummary = eval::RunSummary<Eigen::Vector2d>;

void write_outputs(const std::filesystem::path& dir, const std::string& name, const RunSummary& run,
                   const sim::Ship2DDataset& data, double dt) {
  std::filesystem::create_directories(dir);
  io::CsvWriter csv((dir / (name + "_steps.csv")).string(), {"step", "pose_error", "pose_nees", "seconds"});
  std::vector<io::TumPose> estimated, truth;
  for (std::size_t k = 0; k < run.pose_error.size(); ++k) {
    csv.row({static_cast<double>(k + 1), run.pose_error[k], run.pose_nees[k], run.seconds[k]});
    estimated.push_back(io::tum_pose_from_position((k + 1) * dt, run.trajectory[k]));
    truth.push_back(io::tum_pose_from_position((k + 1) * dt, data.true_poses[k + 1]));
  }
  io::write_tum((dir / (name + "_trajectory.tum")).string(), estimated);
  io::write_tum((dir / "ground_truth.tum").string(), truth);
}

struct Row {
  std::string name;
  eval::Summary summary;
};

void print_table(const std::vector<Row>& rows) {
  std::printf("\n%-27s %13s %12s %13s %16s %15s %11s %14s %s\n", "back-end", "pose MAE[km]", "map MAE[km]",
              "over time[km]", "pose NEES<=5.99", "map NEES<=5.99", "total [s]", "per step [us]", "pose ANEES [95% int.]");
  for (const auto& [name, s] : rows) {
    std::printf("%-27s %13.3f %12.3f %13.3f %15.1f%% %14.1f%% %11.5f %14.2f %.4g", name.c_str(), s.pose_mae, s.map_mae,
                s.map_mae_over_time, 100.0 * s.pose_nees_inside, 100.0 * s.map_nees_inside, s.total_seconds,
                1e6 * s.seconds_per_step, s.pose_anees);
    if (s.anees_interval) std::printf(" [%.3f, %.3f]", s.anees_interval->lower, s.anees_interval->upper);
    std::printf("\n");
  }
  std::printf("%-27s %13.2f %12s %13.3f %16s %15s %11.3f %14s\n", "EKF, thesis (MATLAB)", 19.13, "-", 8.590, "-", "-",
              1.605, "-");
  std::printf("%-27s %13.2f %12s %13.3f %16s %15s %11.3f %14s\n", "Graph, thesis (MATLAB)", 9.91, "-", 7.922, "-", "-",
              3.994, "-");
  std::printf("%-27s %13.2f %12s %13.3f %16s %15s %11.3f %14s\n", "FastSLAM 2.0/50, thesis", 19.71, "-", 13.857, "-", "-",
              12.301, "-");
}

/// Runs `make_backend(data)` on `runs` simulated seeds in parallel and evaluates each run.
template <class MakeBackend>
std::vector<RunSummary> monte_carlo_summaries(const sim::Ship2DOptions& options, int runs, MakeBackend make_backend) {
  return eval::monte_carlo(
      runs, options.seed,
      [&](std::uint64_t seed) {
        sim::Ship2DOptions o = options;
        o.seed = seed;
        const auto data = sim::simulate_ship_2d(o);
        auto backend = make_backend(data);
        if constexpr (requires { backend.optimize(); })
          return eval::evaluate_smoothed_run(backend, data);
        else
          return eval::evaluate_run(backend, data);
      },
      runs == 1 ? 1 : 0);  // one run: no thread, so its timing is not disturbed
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"sextant: the thesis's 2D beacon-ship experiment, every back-end side by side"};
  sim::Ship2DOptions options;
  int runs = 1;
  std::string out_dir;
  app.add_option("--seed", options.seed, "first simulation seed")->capture_default_str();
  app.add_option("--runs", runs, "Monte Carlo runs (seeds seed .. seed+runs-1); the table averages them")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  app.add_option("--steps", options.num_steps, "steps per run")->check(CLI::Range(1, 10000000))->capture_default_str();
  app.add_option("--out", out_dir, "directory for per-step CSV and TUM trajectories of the first run");
  CLI11_PARSE(app, argc, argv);

  try {
    const auto first = sim::simulate_ship_2d(options);
    std::printf("2D beacon ship (thesis §4.2.1): %d steps, %zu beacons, sigma_heading = %.0f deg, %d run(s) from seed %llu\n",
                options.num_steps, first.true_landmarks.size(), options.sigma_heading * 180.0 / std::numbers::pi, runs,
                static_cast<unsigned long long>(options.seed));
    const auto ekf = [](const sim::Ship2DDataset& data) { return ShipEkf{data.motion, data.sensor, data.prior}; };
    const auto seif = [](std::size_t max_active) {
      return [max_active](const sim::Ship2DDataset& data) {
        return ShipSeif{data.motion, data.sensor, data.prior, {.max_active = max_active}};
      };
    };
    std::vector<Row> rows;
    std::vector<RunSummary> ekf_runs;
    for (HeadingNoise noise : {HeadingNoise::unbiased, HeadingNoise::linearized}) {
      sim::Ship2DOptions o = options;
      o.heading_noise = noise;
      const auto summaries = monte_carlo_summaries(o, runs, ekf);
      rows.push_back({noise == HeadingNoise::unbiased ? "EKF-SLAM" : "EKF-SLAM, thesis noise", eval::summarize(summaries, 2, 2)});
      if (noise == options.heading_noise) ekf_runs = summaries;
    }
    rows.push_back({"SEIF-SLAM, 5 active", eval::summarize(monte_carlo_summaries(options, runs, seif(5)), 2, 2)});
    rows.push_back({"SEIF-SLAM, all active", eval::summarize(monte_carlo_summaries(options, runs, seif(0)), 2, 2)});
    const auto graph = [](const sim::Ship2DDataset& data) { return ShipGraph{data.motion, data.sensor, data.prior}; };
    rows.push_back({"GraphSLAM", eval::summarize(monte_carlo_summaries(options, runs, graph), 2, 2)});
    for (FastSlamVersion version : {FastSlamVersion::v1, FastSlamVersion::v2}) {
      const auto fast = [version](const sim::Ship2DDataset& data) {
        return ShipFast{data.motion, data.sensor, data.prior, {.particles = 50, .version = version}};
      };
      rows.push_back({version == FastSlamVersion::v1 ? "FastSLAM 1.0, 50 particles" : "FastSLAM 2.0, 50 particles",
                      eval::summarize(monte_carlo_summaries(options, runs, fast), 2, 2)});
    }
    const RunSummary& first_run = ekf_runs.front();
    print_table(rows);
    const double ekf_seconds = rows.front().summary.total_seconds;
    std::printf("\nEKF total time: %.4f s for %d steps, %.0fx faster than the thesis's 1.605 s\n", ekf_seconds,
                options.num_steps, 1.605 / ekf_seconds);
    if (!out_dir.empty()) {
      write_outputs(out_dir, "ekf", first_run, first, options.dt);
      std::printf("wrote %s/ekf_steps.csv, ekf_trajectory.tum, ground_truth.tum\n", out_dir.c_str());
    }
  } catch (const sextant::error& e) {
    std::fprintf(stderr, "sextant-ship: %s\n", e.what());
    return 1;
  }
  return 0;
}
