#include "common/ranks.hpp"

#include <mpi.h>

#include <cstdlib>

namespace shaker {

bool launched_by_mpi() {
  // OpenMPI's mpirun, and PMI-based launchers (MPICH's hydra, Slurm's srun).
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_RANK"})
    if (std::getenv(name) != nullptr) return true;
  return false;
}

namespace {

bool initialised_here = false;

Ranks make_world() {
  if (!launched_by_mpi()) return Ranks(0, 1);
  int ready = 0;
  MPI_Initialized(&ready);
  if (!ready) {
    MPI_Init(nullptr, nullptr);
    initialised_here = true;
  }
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  return Ranks(rank, size);
}

}  // namespace

const Ranks& Ranks::world() {
  static const Ranks ranks = make_world();
  return ranks;
}

void Ranks::finalize() {
  int finished = 0;
  MPI_Finalized(&finished);
  if (initialised_here && !finished) MPI_Finalize();
}

void Ranks::abort_others(int code) {
  int ready = 0, finished = 0;
  MPI_Initialized(&ready);
  MPI_Finalized(&finished);
  if (!ready || finished || world().size() == 1) return;
  MPI_Abort(MPI_COMM_WORLD, code);
}

std::vector<std::vector<double>> Ranks::gather(const std::vector<double>& mine) const {
  if (size_ == 1) return {mine};
  constexpr int tag = 17;
  if (!root()) {
    MPI_Send(mine.data(), static_cast<int>(mine.size()), MPI_DOUBLE, 0, tag, MPI_COMM_WORLD);
    return {};
  }
  std::vector<std::vector<double>> all(static_cast<std::size_t>(size_));
  all[0] = mine;
  for (int source = 1; source < size_; ++source) {
    MPI_Status status;
    MPI_Probe(source, tag, MPI_COMM_WORLD, &status);
    int count = 0;
    MPI_Get_count(&status, MPI_DOUBLE, &count);
    auto& buffer = all[static_cast<std::size_t>(source)];
    buffer.resize(static_cast<std::size_t>(count));
    MPI_Recv(buffer.data(), count, MPI_DOUBLE, source, tag, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
  }
  return all;
}

}  // namespace shaker
