// The thesis's Table 5 (seed 000, §5.1.3): SEIF-SLAM's pose and map MAE against the number of active
// landmarks on the 2D ship, Monte Carlo averaged over seeds, beside EKF-SLAM and the thesis's numbers.
// Prints a Markdown table (docs/results/seif_active_landmarks.md is its output).
#include <CLI/CLI.hpp>
#include <cstdio>
#include <sextant/sextant.hpp>
#include <string>
#include <vector>

#include "study_program.hpp"

namespace {

using namespace sextant;
using ShipSeif = SeifSlam<BeaconShip2D, BeaconOffset2D>;
using ShipEkf = EkfSlam<BeaconShip2D, BeaconOffset2D>;

struct ThesisRow {
  const char* active;
  double pose, map;
};
// Thesis Table 5 (km).
constexpr ThesisRow kThesis[] = {{"4", 19.8210, 13.6132}, {"5", 19.5655, 13.029},  {"6", 19.7628, 13.2527},
                                 {"7", 19.7833, 13.1154}, {"8", 19.5590, 12.8565}, {"50", 19.5641, 12.4693},
                                 {"all", 19.433, 8.4729}};

/// One seed of a cell: the back-end's scores, and the map MAE after one exact mean recovery.
template <class MakeBackend>
eval::StudyRecord seed_record(const std::string& cell, const std::string& label, const sim::Ship2DOptions& options,
                              std::uint64_t seed, MakeBackend make_backend) {
  sim::Ship2DOptions o = options;
  o.seed = seed;
  const auto data = sim::simulate_ship_2d(o);
  auto backend = make_backend(data);
  eval::StudyRecord record{"ship", cell, label, 2, seed, eval::scores_of(eval::evaluate_run(backend, data), 2, 2), {}, {}};
  if constexpr (requires { backend.recover_mean_exactly(); }) backend.recover_mean_exactly();
  record.extras = {{"map_mae_exact", eval::mean(eval::evaluate_map(backend.map(), data.true_landmarks).errors)}};
  return record;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"sextant: SEIF-SLAM against the number of active landmarks (thesis Table 5)"};
  runner::StudyCommandLine study;
  sim::Ship2DOptions options;
  std::string recovery = "block";
  study.add_to(app);
  app.add_option("--recovery", recovery, "mean recovery: block (joint robot + active) or cd (thesis coordinate descent)")
      ->check(CLI::IsMember({"block", "cd"}))
      ->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  const MeanRecovery mean_recovery = recovery == "cd" ? MeanRecovery::coordinate_descent : MeanRecovery::active_block;
  const std::size_t actives[] = {4, 5, 6, 7, 8, 50, 0};
  const auto seif_cell = [](std::size_t active) { return active == 0 ? std::string("seif-all") : "seif-" + std::to_string(active); };
  const auto seif_label = [](std::size_t active) {
    return active == 0 ? std::string("SEIF, all active") : "SEIF, " + std::to_string(active) + " active";
  };

  try {
    runner::StudyRun run("sextant-seif-study", study, argc, argv);
    options.seed = study.seed;
    run.add_cell([&](std::uint64_t seed) {
      return seed_record("ekf", "EKF-SLAM", options, seed, [](const auto& d) { return ShipEkf{d.motion, d.sensor, d.prior}; });
    });
    for (const std::size_t max_active : actives)
      run.add_cell([&](std::uint64_t seed) {
        return seed_record(seif_cell(max_active), seif_label(max_active), options, seed, [&](const auto& d) {
          return ShipSeif{d.motion, d.sensor, d.prior, {.max_active = max_active, .mean_recovery = mean_recovery}};
        });
      });
    const auto records = run.finish();
    auto print_row = [&](const std::string& cell, const ThesisRow* thesis) {
      const auto runs = runner::cell_records(records, cell);
      if (runs.empty()) return;
      double exact = 0.0;
      for (const auto& r : runs) exact += r.extra("map_mae_exact") / static_cast<double>(runs.size());
      const auto s = eval::summarize(runner::scores_of(runs), 2);
      std::printf("| %s | %.2f ± %.2f | %.2f ± %.2f | %.2f | %s | %.1f%% | %.2f | ", runs.front().label.c_str(), s.pose_mae,
                  s.pose_mae_std, s.map_mae, s.map_mae_std, exact, runner::anees_with_interval(s, "%.3f", 3).c_str(),
                  100.0 * s.pose_nees_inside, 1e6 * s.seconds_per_step);
      if (thesis)
        std::printf("%.2f | %.2f |\n", thesis->pose, thesis->map);
      else
        std::printf("19.13 | 8.59 |\n");
    };
    std::printf("Ship 2D, %d Monte Carlo runs (seeds %llu..%llu), mean recovery: %s\n\n", run.runs(),
                static_cast<unsigned long long>(run.first_seed()),
                static_cast<unsigned long long>(run.first_seed() + run.runs() - 1),
                recovery == "cd" ? "thesis coordinate descent" : "joint robot + active block");
    if (run.part().mode == runner::StudyPart::Mode::shard)
      std::printf("(this shard %s: seeds %s only)\n\n", eval::to_string(run.part().shard).c_str(),
                  eval::to_string(run.part().seeds(study.runs, study.seed)).c_str());
    std::printf("| back-end | pose MAE [km] | map MAE [km] | map MAE after exact recovery [km] | pose ANEES [95%% interval] "
                "| pose NEES <= 5.991 | per step [us] | thesis pose MAE | thesis map MAE |\n");
    std::printf("|---|---|---|---|---|---|---|---|---|\n");
    print_row("ekf", nullptr);
    for (std::size_t i = 0; i < std::size(actives); ++i) print_row(seif_cell(actives[i]), &kThesis[i]);
  } catch (const sextant::error& e) {
    std::fprintf(stderr, "sextant-seif-study: %s\n", e.what());
    return 1;
  }
  return 0;
}
