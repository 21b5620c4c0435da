#pragma once
// The 3D box decomposed horizontally over the ranks of an MPI launch (docs/parallel.md): a
// Cartesian communicator periodic in x and y (px x py ranks, Halo::layout), each rank the
// owner of a block of whole columns with the grid's two ghost layers. This class is the one
// place that talks to MPI for the continuum: the halo exchange of ghost cells, the global
// reductions (time step, energy budget, the implicit diffusion's dot products and plane sums),
// agreement on failures, and the gather to / scatter from the root that make the root the one
// writer of every output and checkpoint.
#include <mpi.h>

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "continuum/grid.hpp"
#include "continuum/state.hpp"

namespace shaker::continuum {

/// The columns of the box one rank owns: x in [i0, i0 + nx), y in [j0, j0 + ny).
struct Block {
  int i0 = 0, j0 = 0, nx = 0, ny = 0;
};

/// How ghost layers travel between ranks. `automatic`: through a window of shared memory
/// (MPI_Win_allocate_shared) when every rank's neighbours are on its own machine, which
/// spares the messages' copies in the kernel; otherwise, and with `messages`, non-blocking
/// messages.
enum class HaloTransport { automatic, messages };

class Halo {
 public:
  /// Fewest cells a rank may own in x or in y: the reconstruction reads two ghost layers, all
  /// of which must come from the one neighbouring rank.
  static constexpr int min_cells_per_rank = 3;

  /// The decomposition of `box` over every rank of the launch (collective). Throws InputError,
  /// naming the sizes and the allowed range, when a rank would own fewer than
  /// min_cells_per_rank cells in x or in y; every rank decides alike.
  Halo(const Grid& box, int ranks, HaloTransport transport = HaloTransport::automatic);
  /// Ranks along x and y for `ranks` in all: MPI_Dims_create's as square a split as `ranks`
  /// allows, with the larger count along y (px <= py), so that the x rows, the contiguous
  /// direction in storage, are cut least: longer runs for the x sweeps, and the ghost layers
  /// sent between ranks are whole rows.
  static std::pair<int, int> layout(int ranks);
  ~Halo();
  Halo(const Halo&) = delete;
  Halo& operator=(const Halo&) = delete;

  const Grid& box() const { return box_; }
  const Grid& local() const { return local_; }  ///< this rank's block, with its ghost layers
  const Block& block() const { return block_; }
  int rank() const { return rank_; }
  int size() const { return size_; }
  bool root() const { return rank_ == 0; }
  int ranks_along(int direction) const { return dims_[direction]; }
  /// Whether ghost layers go through shared memory (HaloTransport).
  bool shares_memory() const { return window_ != MPI_WIN_NULL; }
  /// Bytes of this rank's part of the shared window (0 with messages).
  double shared_bytes() const { return static_cast<double>(4 * (capacity_[0] + capacity_[1]) * sizeof(double)); }
  /// Columns of the whole box: amounts per unit plate area divide by them.
  double plate_columns() const { return static_cast<double>(box_.nx) * box_.ny; }

  /// Fills the x and y ghost layers of the local block's interior planes (k in [0, nz)) of each
  /// field: x first, then y including the x ghosts, so that corner ghosts hold the diagonal
  /// neighbour's cells, as the serial periodic copy does. A direction with one rank copies
  /// locally; otherwise non-blocking messages to and from both neighbours.
  /// `x_filled`: the caller has filled the x ghosts itself (one rank along x only).
  void exchange(const std::vector<double*>& fields, bool x_filled = false) const;

  double sum(double local) const;
  double max(double local) const;
  /// Element-wise sum over the ranks, in place.
  void sum(std::vector<double>& values) const;
  /// The sum of `local` over the ranks on this rank's machine (those sharing its memory), and
  /// their number.
  std::pair<double, int> sum_on_machine(double local) const;
  /// Every rank's `failure` (empty: none); returns true if none failed, else false on every
  /// rank with `failure` set to the message of the lowest failing rank.
  bool agree(std::string& failure) const;
  /// The same, the failure chosen by its `position` (the failing cell's place in the box's
  /// storage order, as a plain run would have met it first; ties to the lower rank).
  bool agree(std::string& failure, std::int64_t position) const;
  /// `value` of the root, on every rank.
  void broadcast(std::vector<double>& values) const;

  /// The interior of every rank's block, into the root's `box_state` (sized to box() there;
  /// untouched elsewhere), in the order of the box: what the serial run holds.
  void gather(const State& local_state, State& box_state) const;
  /// The root's `box_state` interior, split into every rank's block (interior cells only).
  void scatter(const State& box_state, State& local_state) const;

  /// Wall seconds this rank has spent in halo messages and reductions, waiting for the other
  /// ranks included (packing excluded): what the decomposition costs it, for benchmarks.
  double communication_seconds() const { return communication_seconds_; }

 private:
  void exchange_direction(int direction, const std::vector<double*>& fields) const;
  /// The same through the shared-memory window: each rank packs its edge layers into its own
  /// part of the window, and its neighbours unpack them from there after a notification.
  void exchange_shared(int direction, const std::vector<double*>& fields) const;
  /// Allocates the window on the ranks of this machine when every neighbour of every rank is
  /// on its machine (collective); otherwise messages.
  void share_memory_with_neighbours();
  Block block_of(int rank) const;

  /// Every rank's share of the box for gather and scatter, counted in columns of all
  /// variables (`type`: variable_count x nz doubles).
  struct ColumnCounts {
    explicit ColumnCounts(const Halo& halo);
    ColumnCounts(const ColumnCounts&) = delete;
    ColumnCounts& operator=(const ColumnCounts&) = delete;
    ~ColumnCounts();
    /// Where rank r's values start in the root's buffer.
    std::size_t first_value(int r) const {
      return static_cast<std::size_t>(offsets[static_cast<std::size_t>(r)]) * values_per_column;
    }
    int values_per_column;
    MPI_Datatype type = MPI_DATATYPE_NULL;
    std::vector<int> counts, offsets;
  };

  Grid box_, local_;
  Block block_;
  MPI_Comm cartesian_ = MPI_COMM_NULL;
  int rank_ = 0, size_ = 1;
  int dims_[2] = {1, 1};
  int coords_[2] = {0, 0};
  int low_[2] = {0, 0}, high_[2] = {0, 0};  ///< neighbour ranks in x and y
  mutable std::vector<double> send_low_, send_high_, receive_low_, receive_high_;
  /// The shared window (none: messages). A rank's part holds, per direction d, two
  /// generations x two sides (the layers for the low and the high neighbour) of
  /// capacity_[d] doubles from offset_[d]; peers_[d][side] is where the low (0) or high (1)
  /// neighbour's part starts. Successive exchanges along d alternate generations.
  MPI_Comm machine_ = MPI_COMM_NULL;
  MPI_Win window_ = MPI_WIN_NULL;
  std::size_t capacity_[2] = {0, 0}, offset_[2] = {0, 0};
  double* mine_ = nullptr;
  const double* peers_[2][2] = {{nullptr, nullptr}, {nullptr, nullptr}};
  mutable std::uint64_t generation_[2] = {0, 0};
  mutable double communication_seconds_ = 0.0;
};

}  // namespace shaker::continuum
