// The runner's MPI world (mpi_world.hpp): with MPI when the build has it (SEXTANT_HAS_MPI).
#include "mpi_world.hpp"

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "sextant/core/error.hpp"

#ifdef SEXTANT_HAS_MPI
#include <mpi.h>
#endif

namespace sextant::runner::mpi {
namespace {

/// The number of ranks an MPI launcher announced in the environment, or 0 for none.
int announced_size() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_SIZE"})
    if (const char* value = std::getenv(name)) return std::max(1, std::atoi(value));
  if (std::getenv("PMIX_RANK")) return 1;  // a PMIx launch whose size MPI will tell
  return 0;
}

World world;
bool joined = false;

}  // namespace

#ifdef SEXTANT_HAS_MPI

World join() {
  if (joined || announced_size() == 0) return world;
  int initialized = 0;
  MPI_Initialized(&initialized);
  if (!initialized) MPI_Init(nullptr, nullptr);
  joined = true;
  MPI_Comm_rank(MPI_COMM_WORLD, &world.rank);
  MPI_Comm_size(MPI_COMM_WORLD, &world.size);
  MPI_Comm local;
  MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, world.rank, MPI_INFO_NULL, &local);
  MPI_Comm_size(local, &world.local_size);
  MPI_Comm_free(&local);
  return world;
}

std::vector<std::string> gather(const std::string& text) {
  if (!joined || world.size == 1) return {text};
  if (text.size() > static_cast<std::size_t>(INT32_MAX)) throw error("a rank's records exceed 2 GB");
  int length = static_cast<int>(text.size());
  std::vector<int> lengths(world.rank == 0 ? world.size : 0), offsets(lengths.size());
  MPI_Gather(&length, 1, MPI_INT, lengths.data(), 1, MPI_INT, 0, MPI_COMM_WORLD);
  std::string all;
  if (world.rank == 0) {
    long long total = 0;
    for (int r = 0; r < world.size; ++r) {
      offsets[r] = static_cast<int>(total);
      total += lengths[r];
    }
    if (total > INT32_MAX) throw error("the ranks' records exceed 2 GB");
    all.resize(static_cast<std::size_t>(total));
  }
  MPI_Gatherv(text.data(), length, MPI_CHAR, all.data(), lengths.data(), offsets.data(), MPI_CHAR, 0, MPI_COMM_WORLD);
  std::vector<std::string> texts;
  for (int r = 0; r < static_cast<int>(lengths.size()); ++r) texts.push_back(all.substr(offsets[r], lengths[r]));
  return texts;
}

void leave(bool failed) {
  if (!joined) return;
  joined = false;
  std::fflush(stdout);
  if (failed && world.size > 1) MPI_Abort(MPI_COMM_WORLD, 1);
  MPI_Finalize();
}

#else

World join() {
  if (const int size = announced_size(); size > 1)
    throw invalid_input_error("launched by an MPI launcher with " + std::to_string(size) +
                              " ranks, but this build has no MPI (each rank would run the whole study): install "
                              "libopenmpi-dev and build again, or run shards with --shard i/K");
  return world;
}

std::vector<std::string> gather(const std::string& text) { return {text}; }

void leave(bool) {}

#endif

}  // namespace sextant::runner::mpi
