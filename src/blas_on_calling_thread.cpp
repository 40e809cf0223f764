/// Part of every program of the project (through sextant_program_options): OpenBLAS runs on the
/// calling thread (core/blas_threads.hpp says why), set before main, unless OPENBLAS_NUM_THREADS
/// says otherwise.
#include <cstdlib>

#include "sextant/core/blas_threads.hpp"

namespace {
[[maybe_unused]] const bool kBlasOnCallingThread = [] {
  if (std::getenv("OPENBLAS_NUM_THREADS") == nullptr) sextant::run_blas_on_calling_thread();
  return true;
}();
}  // namespace
