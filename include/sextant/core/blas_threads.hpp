#pragma once
/// \file OpenBLAS's thread count, for programs that link sextant::lapack (core/dense_cholesky.hpp).
/// No Eigen here: the project's programs include it in one small file each.

#ifdef SEXTANT_HAS_LAPACK
extern "C" void openblas_set_num_threads(int num_threads);
#endif

namespace sextant {

/// Makes OpenBLAS run every call on the calling thread, process-wide (a no-op without
/// sextant::lapack). OpenBLAS's worker threads spin while they wait, so when the machine is busy (the
/// runner's Monte Carlo threads, a build beside the run) SEIF's thesis-scale run took 6.3-13.4 s
/// with two of them against 3.6-3.9 s with one, and on an idle machine two were no faster
/// (docs/benchmarks.md, round five); only SEIF with ~1000 active landmarks (3000-dimensional
/// blocks) gained from two on an idle machine. Every program of the project calls it before main
/// unless OPENBLAS_NUM_THREADS is set (src/blas_on_calling_thread.cpp); a program of a user that
/// runs filters on several threads should too, or set OPENBLAS_NUM_THREADS=1.
inline void run_blas_on_calling_thread() {
#ifdef SEXTANT_HAS_LAPACK
  openblas_set_num_threads(1);
#endif
}

}  // namespace sextant
