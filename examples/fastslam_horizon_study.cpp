// FastSLAM's consistency against the horizon (issue 34; Bailey, Nieto and Nebot, "Consistency of the
// FastSLAM algorithm", ICRA 2006): the pose NEES of FastSLAM 2.0 averaged over Monte Carlo runs of the
// 2D ship at every step, for several particle counts, against the 95% interval of that average
// (N runs of a consistent filter: chi2(N d) / N). Writes one CSV row per step and prints, per count,
// from which step on the filter is inconsistent: the first step whose next 50 steps' average lies
// above the interval. docs/results/fastslam_horizon.md.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <fstream>
#include <vector>
#include <sextant/sextant.hpp>

namespace {

/// The first step k whose window [k, k + 50) of the average lies above `upper` on average; -1 if none.
long inconsistent_from(const std::vector<double>& average, double upper) {
  constexpr std::size_t window = 50;
  for (std::size_t k = 0; k + window <= average.size(); ++k) {
    double sum = 0.0;
    for (std::size_t j = k; j < k + window; ++j) sum += average[j];
    if (sum / window > upper) return static_cast<long>(k);
  }
  return -1;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace sextant;
  CLI::App app{"sextant: FastSLAM 2.0's pose NEES against time, Monte Carlo averaged (issue 34)"};
  int runs = 20;
  std::uint64_t first_seed = 1;
  std::vector<std::size_t> particle_counts{50, 100, 500, 1000};
  std::string out = "fastslam_horizon.csv";
  app.add_option("--runs", runs, "Monte Carlo runs per particle count")->check(CLI::Range(2, 100000))->capture_default_str();
  app.add_option("--seed", first_seed, "first seed")->capture_default_str();
  app.add_option("--particles", particle_counts, "particle counts (comma-separated)")->delimiter(',')->capture_default_str();
  app.add_option("--out", out, "CSV: step, then the average pose NEES of each count, then the interval")
      ->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  try {
    constexpr int dof = 2;  // the ship's position
    const double n = static_cast<double>(runs);
    const double lower = chi_square_quantile(n * dof, 0.025) / n, upper = chi_square_quantile(n * dof, 0.975) / n;
    std::vector<std::vector<double>> average(particle_counts.size());
    for (std::size_t c = 0; c < particle_counts.size(); ++c)
      for (int r = 0; r < runs; ++r) {
        const std::uint64_t seed = first_seed + static_cast<std::uint64_t>(r);
        const auto data = sim::simulate_ship_2d({.seed = seed});
        FastSlam<BeaconShip2D, BeaconOffset2D> fast{data.motion, data.sensor, data.prior,
                                                    {.particles = particle_counts[c], .resample_threshold = 0.1, .seed = seed}};
        const auto nees = eval::evaluate_run(fast, data).pose_nees;
        average[c].resize(nees.size(), 0.0);
        for (std::size_t k = 0; k < nees.size(); ++k) average[c][k] += nees[k] / n;
      }
    std::ofstream csv(out);
    csv << "step";
    for (std::size_t count : particle_counts) csv << ",nees_" << count;
    csv << ",lower,upper\n";
    for (std::size_t k = 0; k < average.front().size(); ++k) {
      csv << k + 1;
      for (const auto& a : average) csv << ',' << a[k];
      csv << ',' << lower << ',' << upper << '\n';
    }
    std::printf("Ship 2D, FastSLAM 2.0 (resampling below N_eff = 0.1 N), %d runs from seed %llu; the average of %d "
                "consistent runs lies in [%.3f, %.3f] at 95%%\n\n| particles | inconsistent from step | average NEES "
                "over the run | steps above the interval |\n|---|---|---|---|\n",
                runs, static_cast<unsigned long long>(first_seed), runs, lower, upper);
    for (std::size_t c = 0; c < particle_counts.size(); ++c) {
      const auto& a = average[c];
      long above = 0;
      for (double v : a) above += v > upper;
      const long from = inconsistent_from(a, upper);
      std::printf("| %zu | %s | %.3g | %.1f%% |\n", particle_counts[c], from < 0 ? "never" : std::to_string(from + 1).c_str(),
                  eval::mean(a), 100.0 * static_cast<double>(above) / static_cast<double>(a.size()));
    }
    std::printf("\nper-step averages: %s\n", out.c_str());
  } catch (const sextant::error& e) {
    std::fprintf(stderr, "sextant-fastslam-horizon: %s\n", e.what());
    return 1;
  }
  return 0;
}
