// The thesis's Table 7 (seed 000, §5.1.3): FastSLAM's pose and map MAE against the number of
// particles on the 2D ship, for FastSLAM 1.0 and 2.0, Monte Carlo averaged over seeds, with the pose
// ANEES (the thesis could not compute it). Prints a Markdown table (docs/results/fastslam_particles.md).
#include <CLI/CLI.hpp>
#include <cstdio>
#include <vector>
#include <sextant/sextant.hpp>

int main(int argc, char** argv) {
  using namespace sextant;
  CLI::App app{"sextant: FastSLAM against the number of particles (thesis Table 7)"};
  int runs = 20;
  sim::Ship2DOptions options;
  app.add_option("--runs", runs, "Monte Carlo runs")->check(CLI::Range(2, 100000))->capture_default_str();
  app.add_option("--seed", options.seed, "first seed")->capture_default_str();
  double resample_threshold = FastSlamOptions{}.resample_threshold;
  app.add_option("--resample-threshold", resample_threshold, "resample when N_eff < threshold * N")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  std::vector<std::size_t> particle_counts{5, 10, 20, 50, 100, 300, 1000};
  app.add_option("--particles", particle_counts, "particle counts (comma-separated)")->delimiter(',')->capture_default_str();
  std::vector<int> versions{1, 2};
  app.add_option("--version", versions, "FastSLAM versions (1, 2 or 1,2)")->delimiter(',')->check(CLI::IsMember({1, 2}))
      ->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  // Thesis Table 7, FastSLAM 2.0 (its units say m; the data is in km like Tables 4-6).
  const std::map<std::size_t, std::pair<double, double>> thesis{
      {5, {21.2005, 14.6202}}, {10, {15.9390, 11.6669}}, {20, {38.4606, 19.0153}}, {50, {19.7086, 13.8570}}};
  try {
    std::printf("Ship 2D, %d Monte Carlo runs (seeds %llu..%llu)\n\n", runs, static_cast<unsigned long long>(options.seed),
                static_cast<unsigned long long>(options.seed + runs - 1));
    std::printf("| version | particles | pose MAE [km] | map MAE [km] | pose ANEES [95%% interval] | pose NEES <= 5.991 "
                "| per step [us] | thesis 2.0 pose / map MAE |\n|---|---|---|---|---|---|---|---|\n");
    for (int version_number : versions) {
      const FastSlamVersion version = version_number == 1 ? FastSlamVersion::v1 : FastSlamVersion::v2;
      for (std::size_t particles : particle_counts) {
        const auto results = eval::monte_carlo(runs, options.seed, [&](std::uint64_t seed) {
          sim::Ship2DOptions o = options;
          o.seed = seed;
          const auto data = sim::simulate_ship_2d(o);
          FastSlam<BeaconShip2D, BeaconOffset2D> fast{data.motion, data.sensor, data.prior,
                                                      {.particles = particles, .version = version, .resample_threshold = resample_threshold, .seed = seed}};
          return eval::evaluate_run(fast, data);
        });
        const auto s = eval::summarize(results, 2, 2);
        std::printf("| %s | %zu | %.2f ± %.2f | %.2f ± %.2f | %.3g [%.2f, %.2f] | %.1f%% | %.1f | ",
                    version == FastSlamVersion::v1 ? "1.0" : "2.0", particles, s.pose_mae, s.pose_mae_std, s.map_mae,
                    s.map_mae_std, s.pose_anees, s.anees_interval->lower, s.anees_interval->upper,
                    100.0 * s.pose_nees_inside, 1e6 * s.seconds_per_step);
        const auto it = thesis.find(particles);
        if (version == FastSlamVersion::v2 && it != thesis.end())
          std::printf("%.2f / %.2f |\n", it->second.first, it->second.second);
        else
          std::printf("– |\n");
        std::fflush(stdout);
      }
    }
  } catch (const sextant::error& e) {
    std::fprintf(stderr, "sextant-fastslam-study: %s\n", e.what());
    return 1;
  }
  return 0;
}
