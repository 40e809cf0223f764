// sextant-run's ship part: every chosen back-end on the simulated ship, Monte Carlo over seeds.
#include "dataset_runner.hpp"

namespace sextant::runner {

std::vector<TableRow> run_ship(const RunOptions& options, const std::vector<BackendKind>& kinds, const RunnerConfig& config) {
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

}  // namespace sextant::runner
