#pragma once
// The runner's data-set families, one registry for every program: how a --dataset argument is
// recognized, which program runs it, its help line (dataset_registry.cpp, one line per family); and
// each family's run, registered by the translation unit that defines it (RegisterDatasetRun), which
// only its program compiles. Adding a family: one file that defines and registers its run, one line
// in the registry (docs/runner.md, "Add your own dataset").
#include <string>
#include <vector>

#include "runner_cli.hpp"

namespace sextant::runner {

/// A family of data sets.
struct DatasetFamily {
  const char* key;                               ///< the name its run is registered under
  const char* syntax;                            ///< how --dataset names it (help text, messages)
  const char* program;                           ///< the program that runs it
  bool (*recognizes)(const std::string& dataset);
  const char* help;                              ///< one line for --help
  bool seeded = false;  ///< a Monte Carlo over seeds, which --shard and mpirun split (monte_carlo_study.hpp)
};

/// Every family, in the order a --dataset argument is tried against them (the catch-all last).
const std::vector<DatasetFamily>& dataset_families();

/// The family that recognizes `dataset`; throws invalid_input_error when none does.
const DatasetFamily& family_of(const std::string& dataset);

/// A program of the runner: sextant-run and the programs it hands families over to.
struct RunnerProgram {
  const char* name;
  const char* description;           ///< first line of --help
  const char* runs;                  ///< what it runs, for the message that refuses the rest
  std::vector<std::string> defaults;  ///< its data sets without --dataset
};
const RunnerProgram& runner_program(const std::string& name);

/// The --dataset option's help in `program`: every family's syntax, and the program's defaults.
std::string dataset_help(const std::string& program);

/// Registers a family's run in the program that compiles it: a namespace-scope
/// `const RegisterDatasetRun registration{"key", run};` in the family's file.
struct RegisterDatasetRun {
  RegisterDatasetRun(const char* key, DatasetRun run);
};

/// The run registered under `key` in this program; throws invalid_input_error when it has none.
DatasetRun registered_run(const std::string& key);

/// main() of every runner program (program_main.cpp): the options; then the data sets, each run by
/// its family's registered run, or (sextant-run only) handed over to the program of their family.
int program_main(int argc, char** argv, const char* program);

}  // namespace sextant::runner
