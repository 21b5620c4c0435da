#pragma once
// The processes of one run: the ranks of an MPI launch (`mpirun -np P shaker ...`), or a single
// rank when the program is started on its own. MPI is initialised only when a launcher started
// the process, so a plain run never depends on an MPI runtime being usable.
#include <string>
#include <vector>

namespace shaker {

class Ranks {
 public:
  /// The ranks of this process's launch; MPI is initialised on the first call under a launcher.
  static const Ranks& world();
  /// Finalises MPI if it was initialised (idempotent); call before leaving main.
  static void finalize();
  /// Ends every rank of a launch with `code` after a failure on this rank alone, which would
  /// otherwise leave the others waiting for it; returns without effect outside a launch of
  /// several ranks.
  static void abort_others(int code);

  int rank() const { return rank_; }
  int size() const { return size_; }
  bool root() const { return rank_ == 0; }

  Ranks(int rank, int size) : rank_(rank), size_(size) {}

  /// Compares every rank's `text` (its effective configuration) with the root's; if any differs,
  /// throws InputError on every rank alike, naming the lowest such rank and the first key (or
  /// line) that differs, with both values. Without effect on a single rank.
  void require_same_configuration(const std::string& text) const;

  /// Every rank's buffer, at the root in rank order; other ranks get an empty list.
  std::vector<std::vector<double>> gather(const std::vector<double>& mine) const;

 private:
  int rank_, size_;
};

/// True if an MPI launcher started this process (its environment says how many ranks).
bool launched_by_mpi();

}  // namespace shaker
