// The thesis's Table 5 (seed 000, §5.1.3): SEIF-SLAM's pose and map MAE against the number of active
// landmarks on the 2D ship, Monte Carlo averaged over seeds, beside EKF-SLAM and the thesis's numbers.
// Prints a Markdown table (docs/results/seif_active_landmarks.md is its output).
#include <CLI/CLI.hpp>
#include <cstdio>
#include <sextant/sextant.hpp>
#include <string>
#include <vector>

namespace {

using namespace sextant;
using ShipSeif = SeifSlam<BeaconShip2D, BeaconOffset2D>;
using ShipEkf = EkfSlam<BeaconShip2D, BeaconOffset2D>;

struct Scored {
  eval::RunSummary<Eigen::Vector2d> run;
  double map_mae_exact = 0.0;  ///< map MAE after one exact mean recovery at the end
  std::size_t active_at_end = 0;
};

struct ThesisRow {
  const char* active;
  double pose, map;
};
// Thesis Table 5 (km).
constexpr ThesisRow kThesis[] = {{"4", 19.8210, 13.6132}, {"5", 19.5655, 13.029},  {"6", 19.7628, 13.2527},
                                 {"7", 19.7833, 13.1154}, {"8", 19.5590, 12.8565}, {"50", 19.5641, 12.4693},
                                 {"all", 19.433, 8.4729}};

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"sextant: SEIF-SLAM against the number of active landmarks (thesis Table 5)"};
  int runs = 20;
  sim::Ship2DOptions options;
  std::string recovery = "block";
  app.add_option("--runs", runs, "Monte Carlo runs")->check(CLI::Range(2, 100000))->capture_default_str();
  app.add_option("--seed", options.seed, "first seed")->capture_default_str();
  app.add_option("--recovery", recovery, "mean recovery: block (joint robot + active) or cd (thesis coordinate descent)")
      ->check(CLI::IsMember({"block", "cd"}))
      ->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  const MeanRecovery mean_recovery = recovery == "cd" ? MeanRecovery::coordinate_descent : MeanRecovery::active_block;

  try {
    auto score = [&](auto make_backend) {
      return eval::monte_carlo(runs, options.seed, [&](std::uint64_t seed) {
        sim::Ship2DOptions o = options;
        o.seed = seed;
        const auto data = sim::simulate_ship_2d(o);
        auto backend = make_backend(data);
        Scored out{eval::evaluate_run(backend, data), 0.0, 0};
        if constexpr (requires { backend.recover_mean_exactly(); }) {
          out.active_at_end = backend.active_landmarks().size();
          backend.recover_mean_exactly();
        }
        out.map_mae_exact = eval::mean(eval::evaluate_map(backend.map(), data.true_landmarks).errors);
        return out;
      });
    };
    auto print_row = [&](const std::string& name, const std::vector<Scored>& scored, const ThesisRow* thesis) {
      std::vector<eval::RunSummary<Eigen::Vector2d>> plain;
      double exact = 0.0;
      for (const auto& s : scored) {
        plain.push_back(s.run);
        exact += s.map_mae_exact / static_cast<double>(scored.size());
      }
      const auto s = eval::summarize(plain, 2, 2);
      std::printf("| %s | %.2f ± %.2f | %.2f ± %.2f | %.2f | %.3f [%.3f, %.3f] | %.1f%% | %.2f | ", name.c_str(),
                  s.pose_mae, s.pose_mae_std, s.map_mae, s.map_mae_std, exact, s.pose_anees, s.anees_interval->lower,
                  s.anees_interval->upper, 100.0 * s.pose_nees_inside, 1e6 * s.seconds_per_step);
      if (thesis)
        std::printf("%.2f | %.2f |\n", thesis->pose, thesis->map);
      else
        std::printf("19.13 | 8.59 |\n");
    };
    std::printf("Ship 2D, %d Monte Carlo runs (seeds %llu..%llu), mean recovery: %s\n\n", runs,
                static_cast<unsigned long long>(options.seed), static_cast<unsigned long long>(options.seed + runs - 1),
                recovery == "cd" ? "thesis coordinate descent" : "joint robot + active block");
    std::printf("| back-end | pose MAE [km] | map MAE [km] | map MAE after exact recovery [km] | pose ANEES [95%% interval] "
                "| pose NEES <= 5.991 | per step [us] | thesis pose MAE | thesis map MAE |\n");
    std::printf("|---|---|---|---|---|---|---|---|---|\n");
    print_row("EKF-SLAM", score([](const auto& d) { return ShipEkf{d.motion, d.sensor, d.prior}; }), nullptr);
    const std::size_t actives[] = {4, 5, 6, 7, 8, 50, 0};
    for (std::size_t i = 0; i < std::size(actives); ++i) {
      const std::size_t max_active = actives[i];
      const auto scored = score([&](const auto& d) {
        return ShipSeif{d.motion, d.sensor, d.prior, {.max_active = max_active, .mean_recovery = mean_recovery}};
      });
      print_row(max_active == 0 ? "SEIF, all active" : "SEIF, " + std::to_string(max_active) + " active", scored,
                &kThesis[i]);
    }
  } catch (const sextant::error& e) {
    std::fprintf(stderr, "sextant-seif-study: %s\n", e.what());
    return 1;
  }
  return 0;
}
