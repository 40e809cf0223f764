// The thesis's Table 7 (seed 000, §5.1.3): FastSLAM's pose and map MAE against the number of
// particles on the 2D ship, for FastSLAM 1.0 and 2.0, Monte Carlo averaged over seeds, with the pose
// ANEES (the thesis could not compute it). Prints a Markdown table (docs/results/fastslam_particles.md).
#include <CLI/CLI.hpp>
#include <cstdio>
#include <vector>
#include <sextant/sextant.hpp>

#include "study_program.hpp"

int main(int argc, char** argv) {
  using namespace sextant;
  CLI::App app{"sextant: FastSLAM against the number of particles (thesis Table 7)"};
  runner::StudyCommandLine study;
  study.add_to(app);
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
  const auto cell = [](int version, std::size_t particles) {
    return "fastslam" + std::to_string(version) + "-" + std::to_string(particles);
  };
  try {
    runner::StudyRun run("sextant-fastslam-study", study, argc, argv);
    for (int version_number : versions) {
      const FastSlamVersion version = version_number == 1 ? FastSlamVersion::v1 : FastSlamVersion::v2;
      for (std::size_t particles : particle_counts)
        run.add_cell([&](std::uint64_t seed) {
          sim::Ship2DOptions o;
          o.seed = seed;
          const auto data = sim::simulate_ship_2d(o);
          FastSlam<BeaconShip2D, BeaconOffset2D> fast{data.motion, data.sensor, data.prior,
                                                      {.particles = particles, .version = version, .resample_threshold = resample_threshold, .seed = seed}};
          return eval::StudyRecord{"ship", cell(version_number, particles), cell(version_number, particles), 2, seed,
                                   eval::scores_of(eval::evaluate_run(fast, data), 2, 2), {}, {}};
        });
    }
    const auto records = run.finish();
    std::printf("Ship 2D, %d Monte Carlo runs (seeds %llu..%llu)\n\n", run.runs(),
                static_cast<unsigned long long>(run.first_seed()),
                static_cast<unsigned long long>(run.first_seed() + run.runs() - 1));
    if (run.part().mode == runner::StudyPart::Mode::shard)
      std::printf("(this shard %s: seeds %s only)\n\n", eval::to_string(run.part().shard).c_str(),
                  eval::to_string(run.part().seeds(study.runs, study.seed)).c_str());
    std::printf("| version | particles | pose MAE [km] | map MAE [km] | pose ANEES [95%% interval] | pose NEES <= 5.991 "
                "| per step [us] | thesis 2.0 pose / map MAE |\n|---|---|---|---|---|---|---|---|\n");
    for (int version : versions)
      for (std::size_t particles : particle_counts) {
        const auto runs = runner::cell_records(records, cell(version, particles));
        if (runs.empty()) continue;
        const auto s = eval::summarize(runner::scores_of(runs), 2);
        std::printf("| %s | %zu | %.2f ± %.2f | %.2f ± %.2f | %s | %.1f%% | %.1f | ", version == 1 ? "1.0" : "2.0",
                    particles, s.pose_mae, s.pose_mae_std, s.map_mae, s.map_mae_std,
                    runner::anees_with_interval(s, "%.3g", 2).c_str(), 100.0 * s.pose_nees_inside, 1e6 * s.seconds_per_step);
        const auto it = thesis.find(particles);
        if (version == 2 && it != thesis.end())
          std::printf("%.2f / %.2f |\n", it->second.first, it->second.second);
        else
          std::printf("– |\n");
      }
  } catch (const sextant::error& e) {
    std::fprintf(stderr, "sextant-fastslam-study: %s\n", e.what());
    return 1;
  }
  return 0;
}
