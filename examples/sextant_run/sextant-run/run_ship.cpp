// sextant-run's ship part: every chosen back-end on the simulated ship, Monte Carlo over seeds.
#include "dataset_registry.hpp"
#include "dataset_runner.hpp"

namespace sextant::runner {
namespace {

std::vector<TableRow> run_ship(const CliOptions& cli, const std::string&, const std::vector<BackendKind>& kinds,
                               const RunnerConfig& config) {
  std::printf("\n== ship: the thesis's 2D beacon ship, %d steps, %d Monte Carlo run(s) from seed %llu; errors in km\n",
              config.ship.num_steps, config.ship_runs, static_cast<unsigned long long>(config.ship.seed));
  print_header();
  std::vector<std::pair<BackendKind, BackendRun<sim::Ship2DDataset>>> runs;
  auto rows = run_on_ship(kinds, config, runs);
  for (const auto& row : rows) print_row(row);
  write_dataset_outputs(cli.output, "ship", sim::simulate_ship_2d(config.ship), runs, config, "km");
  return rows;
}

const RegisterDatasetRun registration{"ship", run_ship};

}  // namespace

}  // namespace sextant::runner
