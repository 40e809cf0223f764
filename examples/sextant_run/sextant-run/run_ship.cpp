// sextant-run's ship part: every chosen back-end on the simulated ship, Monte Carlo over seeds.
#include "dataset_registry.hpp"
#include "dataset_runner.hpp"

namespace sextant::runner {
namespace {

/// The study's seeds this process runs (all of them, or its shard's), their records, and the table of
/// the records it holds after study_records (all of them but in a shard; none at MPI's other ranks).
std::vector<TableRow> run_ship(const CliOptions& cli, const std::string&, const std::vector<BackendKind>& kinds,
                               const RunnerConfig& config) {
  const auto seeds = cli.study.seeds(config.ship_runs, config.ship.seed);
  std::printf("\n== ship: the thesis's 2D beacon ship, %d steps, %d Monte Carlo run(s) from seed %llu", config.ship.num_steps,
              config.ship_runs, static_cast<unsigned long long>(config.ship.seed));
  if (cli.study.mode == StudyPart::Mode::shard)
    std::printf(" (this shard %s: seeds %s only)", eval::to_string(cli.study.shard).c_str(), eval::to_string(seeds).c_str());
  std::printf("; errors in km\n");
  std::vector<std::pair<BackendKind, BackendRun<sim::Ship2DDataset>>> first_runs;
  auto records = ship_records(kinds, config, seeds, cli.study.threads, first_runs);
  const auto rows = rows_of(study_records(cli.study, std::move(records), config.ship_runs, config.ship.seed, cli.output.out));
  print_header();
  for (const auto& row : rows) print_row(row);
  if (!first_runs.empty()) write_dataset_outputs(cli.output, "ship", sim::simulate_ship_2d(config.ship), first_runs, config, "km");
  return rows;
}

const RegisterDatasetRun registration{"ship", run_ship};

}  // namespace

}  // namespace sextant::runner
