// The thesis's 2D beacon-ship experiment (seed 000, §4.2.1, Tables 4 and 11): simulate, filter with
// every back-end, and print accuracy, consistency and time side by side; optionally write per-step
// CSV and TUM trajectories, and Monte Carlo ANEES over many seeds.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <filesystem>
#include <sextant/sextant.hpp>
#include <string>
#include <vector>

namespace {

using namespace sextant;
using ShipEkf = EkfSlam<BeaconShip2D, BeaconOffset2D>;

/// Accuracy, consistency and time of one back-end on one simulated run.
struct RunSummary {
  std::vector<double> pose_error, pose_nees, seconds;
  std::vector<double> map_error, map_nees;  // final map, per landmark
  std::vector<Eigen::Vector2d> trajectory;   // estimated pose after each step
  double total_seconds = 0.0;
};

template <class Backend>
RunSummary evaluate(Backend& backend, const sim::Ship2DDataset& data) {
  RunSummary out;
  const auto record = eval::run(backend, data.steps);
  for (std::size_t k = 0; k < record.steps.size(); ++k) {
    const auto& pose = record.steps[k].pose;
    const Eigen::Vector2d error = pose.mean - data.true_poses[k + 1];
    out.pose_error.push_back(error.norm());
    out.pose_nees.push_back(eval::nees(error, pose.cov));
    out.seconds.push_back(record.steps[k].seconds);
    out.trajectory.push_back(pose.mean);
  }
  auto map = eval::evaluate_map(backend.map(), data.true_landmarks);
  out.map_error = std::move(map.errors);
  out.map_nees = std::move(map.nees);
  out.total_seconds = record.total_seconds;
  return out;
}

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
  double pose_mae, map_mae, pose_inside, map_inside, total_seconds, per_step_us;
  std::string anees;
};

void print_table(const std::vector<Row>& rows, int runs) {
  std::printf("\n%-22s %13s %12s %16s %15s %11s %14s %s\n", "back-end", "pose MAE[km]", "map MAE[km]",
              "pose NEES<=5.99", "map NEES<=5.99", "total [s]", "per step [us]", runs > 1 ? "pose ANEES [95% int.]" : "");
  for (const auto& r : rows)
    std::printf("%-22s %13.3f %12.3f %15.1f%% %14.1f%% %11.5f %14.2f %s\n", r.name.c_str(), r.pose_mae, r.map_mae,
                r.pose_inside, r.map_inside, r.total_seconds, r.per_step_us, r.anees.c_str());
  std::printf("%-22s %13.2f %12.3f %16s %15s %11.3f %14s\n", "EKF, thesis (MATLAB)", 19.13, 8.590, "-", "-", 1.605,
              "-");
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
        return evaluate(backend, data);
      },
      runs == 1 ? 1 : 0);  // one run: no thread, so its timing is not disturbed
}

/// Averages the runs into one table row; with several runs, the pose ANEES and its interval.
Row summarize(const std::string& name, const std::vector<RunSummary>& summaries) {
  const double runs = static_cast<double>(summaries.size());
  Row row{name, 0, 0, 0, 0, 0, 0, ""};
  std::vector<std::vector<double>> nees_runs;
  for (const auto& s : summaries) {
    row.pose_mae += eval::mean(s.pose_error) / runs;
    row.map_mae += eval::mean(s.map_error) / runs;
    row.pose_inside += 100.0 * eval::fraction_at_most(s.pose_nees, eval::nees_upper_bound(2)) / runs;
    row.map_inside += 100.0 * eval::fraction_at_most(s.map_nees, eval::nees_upper_bound(2)) / runs;
    row.total_seconds += s.total_seconds / runs;
    nees_runs.push_back(s.pose_nees);
  }
  row.per_step_us = 1e6 * row.total_seconds / static_cast<double>(summaries.front().pose_error.size());
  if (summaries.size() > 1) {
    const auto interval = eval::anees_interval(2, static_cast<int>(summaries.size()));
    char text[96];
    std::snprintf(text, sizeof text, "%.3f [%.3f, %.3f]", eval::mean(eval::anees_per_step(nees_runs)), interval.lower,
                  interval.upper);
    row.anees = text;
  }
  return row;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"sextant: the thesis's 2D beacon-ship experiment (EKF-SLAM)"};
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
    std::vector<Row> rows;
    RunSummary first_run;
    for (HeadingNoise noise : {HeadingNoise::unbiased, HeadingNoise::linearized}) {
      sim::Ship2DOptions o = options;
      o.heading_noise = noise;
      const auto summaries = monte_carlo_summaries(o, runs, ekf);
      rows.push_back(summarize(noise == HeadingNoise::unbiased ? "EKF-SLAM" : "EKF-SLAM, thesis noise", summaries));
      if (noise == options.heading_noise) first_run = summaries.front();
    }
    print_table(rows, runs);
    std::printf("\nEKF total time: %.4f s for %d steps, %.0fx faster than the thesis's 1.605 s\n", rows.front().total_seconds,
                options.num_steps, 1.605 / rows.front().total_seconds);
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
