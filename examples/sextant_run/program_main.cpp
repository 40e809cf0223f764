// main() of each runner program: the build names the program (SEXTANT_RUNNER_PROGRAM), whose data-set
// families' runs are the other files compiled into it (dataset_registry.hpp, docs/runner.md).
#include "dataset_registry.hpp"

int main(int argc, char** argv) { return sextant::runner::program_main(argc, argv, SEXTANT_RUNNER_PROGRAM); }
