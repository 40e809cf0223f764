// main() of each runner program: the build names the program (SEXTANT_RUNNER_PROGRAM), whose data-set
// families' runs are the other files compiled into it (dataset_registry.hpp, docs/runner.md).
#include "build_configuration.hpp"
#include "dataset_registry.hpp"

// The units of this program were compiled with the macros the headers were (build_configuration.hpp).
#ifdef SEXTANT_HAS_CHOLMOD
static_assert(sextant::runner::build::has_cholmod, "the runner's precompiled header was built without SEXTANT_HAS_CHOLMOD");
#else
static_assert(!sextant::runner::build::has_cholmod, "the runner's precompiled header was built with SEXTANT_HAS_CHOLMOD");
#endif
#ifdef SEXTANT_HAS_LAPACK
static_assert(sextant::runner::build::has_lapack, "the runner's precompiled header was built without SEXTANT_HAS_LAPACK");
#else
static_assert(!sextant::runner::build::has_lapack, "the runner's precompiled header was built with SEXTANT_HAS_LAPACK");
#endif
#ifdef SEXTANT_COMPILED_INSTANCES
static_assert(sextant::runner::build::compiled_instances,
              "the runner's precompiled header was built without SEXTANT_COMPILED_INSTANCES");
#else
static_assert(!sextant::runner::build::compiled_instances,
              "the runner's precompiled header was built with SEXTANT_COMPILED_INSTANCES");
#endif

int main(int argc, char** argv) { return sextant::runner::program_main(argc, argv, SEXTANT_RUNNER_PROGRAM); }
