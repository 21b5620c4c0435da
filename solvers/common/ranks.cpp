#include "common/ranks.hpp"

#include <mpi.h>

#include <fmt/format.h>

#include <algorithm>
#include <cstdlib>
#include <sstream>

#include "common/errors.hpp"

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

namespace {

/// `text` of rank `from` on every rank.
std::string broadcast(std::string text, int from) {
  long long size = static_cast<long long>(text.size());
  MPI_Bcast(&size, 1, MPI_LONG_LONG, from, MPI_COMM_WORLD);
  text.resize(static_cast<std::size_t>(size));
  MPI_Bcast(text.data(), static_cast<int>(size), MPI_CHAR, from, MPI_COMM_WORLD);
  return text;
}

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

/// The first difference of two configurations (TOML of one schema): "KEY = VALUE where rank 0
/// has KEY = VALUE", the key with its [section].
std::string first_difference(const std::string& mine, const std::string& root) {
  const std::vector<std::string> a = lines_of(mine), b = lines_of(root);
  std::string section;
  for (std::size_t k = 0; k < std::max(a.size(), b.size()); ++k) {
    const std::string x = k < a.size() ? a[k] : "(nothing)", y = k < b.size() ? b[k] : "(nothing)";
    if (x == y) {
      if (x.starts_with('[') && x.ends_with(']')) section = x.substr(1, x.size() - 2) + ".";
      continue;
    }
    const bool keys = x.find(" = ") != std::string::npos && y.find(" = ") != std::string::npos;
    return keys ? fmt::format("{}{} where rank 0 has {}{}", section, x, section, y)
                : fmt::format("'{}' where rank 0 has '{}'", x, y);
  }
  return "the same lines";
}

}  // namespace

void Ranks::require_same_configuration(const std::string& text) const {
  if (size_ == 1) return;
  const std::string root_text = broadcast(root() ? text : std::string(), 0);
  int mine = text == root_text ? size_ : rank_, lowest = size_;
  MPI_Allreduce(&mine, &lowest, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  if (lowest == size_) return;
  const std::string difference = broadcast(rank_ == lowest ? first_difference(text, root_text) : std::string(), lowest);
  throw InputError(fmt::format("the {} ranks of this launch disagree on the effective configuration: rank {} "
                               "has {}; allowed: the same case file and --set values on every rank",
                               size_, lowest, difference));
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
