#pragma once
// MPI for the runner's Monte Carlo studies, optional (docs/monte_carlo_clusters.md): a process that
// mpirun (or srun) launched joins the world of its ranks; any other process runs alone, with or
// without MPI in the build. mpi_world.cpp is compiled with MPI when CMake found it
// (SEXTANT_HAS_MPI) and without it otherwise.
#include <string>
#include <vector>

namespace sextant::runner::mpi {

/// This process among the ranks of its launch: rank 0 of 1 when it was not launched by MPI.
struct World {
  int rank = 0, size = 1;
  int local_size = 1;  ///< ranks on this machine (they share its cores)
};

/// Joins MPI when the environment says an MPI launcher started this process (OMPI_COMM_WORLD_SIZE,
/// PMI_SIZE or PMIX_RANK); throws when it did with several ranks and the build has no MPI, since each
/// rank would then run the whole study. Idempotent.
World join();

/// At rank 0: every rank's `text`, in rank order; at the other ranks: nothing. Collective.
std::vector<std::string> gather(const std::string& text);

/// Leaves MPI (MPI_Finalize) after a run that ended well, or ends every rank (MPI_Abort) after one
/// that failed: the other ranks would wait in gather for ever. Nothing when MPI was not joined.
void leave(bool failed);

}  // namespace sextant::runner::mpi
