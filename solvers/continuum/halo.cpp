#include "continuum/halo.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <exception>
#include <limits>
#include <tuple>

#include "common/errors.hpp"

namespace shaker::continuum {

namespace {

/// [first, first + length) of the `parts` near-equal pieces of `cells`, piece `part`.
std::pair<int, int> piece(int cells, int parts, int part) {
  const int first = static_cast<int>(static_cast<std::int64_t>(part) * cells / parts);
  const int end = static_cast<int>(static_cast<std::int64_t>(part + 1) * cells / parts);
  return {first, end - first};
}

/// Calls visit(storage index) for every cell of one layer of the block, in the same order on
/// both ranks of a message. `first` is the layer's first coordinate along `direction`; x layers
/// span the interior rows, y layers the x ghosts too.
template <class Visit> void for_layer(const Grid& g, int direction, int first, Visit visit) {
  const int G = Grid::ghosts;
  for (int k = 0; k < g.nz; ++k) {
    if (direction == 0) {
      for (int j = 0; j < g.ny; ++j)
        for (int m = 0; m < G; ++m) visit(g.index(first + m, j, k));
    } else {
      for (int m = 0; m < G; ++m)
        for (int i = -G; i < g.nx + G; ++i) visit(g.index(i, first + m, k));
    }
  }
}

/// Copies the layer starting at `first` along `direction` of every field, field after field,
/// to `to` (pack) or from `from` (unpack): the order both ranks of a message share.
void pack_layers(const Grid& g, int direction, int first, const std::vector<double*>& fields, double* to) {
  for (const double* field : fields) for_layer(g, direction, first, [&](std::ptrdiff_t c) { *to++ = field[c]; });
}
void unpack_layers(const Grid& g, int direction, int first, const std::vector<double*>& fields, const double* from) {
  for (double* field : fields) for_layer(g, direction, first, [&](std::ptrdiff_t c) { field[c] = *from++; });
}

/// Doubles in one ghost layer set (Grid::ghosts deep) of a block along direction d.
std::size_t layer_size(const Grid& box, const Block& b, int d) {
  return static_cast<std::size_t>(Grid::ghosts) * box.nz * (d == 0 ? b.ny : b.nx + 2 * Grid::ghosts);
}

constexpr int tag_downwards = 0, tag_upwards = 1;

/// Adds the wall seconds of its lifetime to `total`.
class Stopwatch {
 public:
  explicit Stopwatch(double& total) : total_(total), start_(std::chrono::steady_clock::now()) {}
  ~Stopwatch() { total_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count(); }
  Stopwatch(const Stopwatch&) = delete;
  Stopwatch& operator=(const Stopwatch&) = delete;

 private:
  double& total_;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace

Halo::Halo(const Grid& box, int ranks, HaloTransport transport) : box_(box), local_(box) {
  std::tie(dims_[0], dims_[1]) = layout(ranks);
  const int fewest_x = box.nx / dims_[0], fewest_y = box.ny / dims_[1];
  if (fewest_x < min_cells_per_rank || fewest_y < min_cells_per_rank)
    throw InputError(fmt::format(
        "the 3D box of {} x {} cells (continuum.box_width and continuum.box_depth / continuum.cell_size) cannot be split "
        "over {} ranks: split as {} x {} ranks (x by y), {} x {} cells or fewer each; allowed: "
        "at least {} cells per rank in x and in y, so at most {} ranks in x and {} in y (fewer "
        "ranks, or a wider box)",
        box.nx, box.ny, ranks, dims_[0], dims_[1], fewest_x, fewest_y, min_cells_per_rank,
        box.nx / min_cells_per_rank, box.ny / min_cells_per_rank));
  const int periodic[2] = {1, 1};
  // No reordering: rank 0 of the launch stays the root that reads and writes.
  MPI_Cart_create(MPI_COMM_WORLD, 2, dims_, periodic, 0, &cartesian_);
  MPI_Comm_rank(cartesian_, &rank_);
  MPI_Comm_size(cartesian_, &size_);
  MPI_Cart_coords(cartesian_, rank_, 2, coords_);
  for (int d = 0; d < 2; ++d) MPI_Cart_shift(cartesian_, d, 1, &low_[d], &high_[d]);
  block_ = block_of(rank_);
  local_.nx = block_.nx;
  local_.ny = block_.ny;
  if (transport == HaloTransport::automatic && size_ > 1) share_memory_with_neighbours();
}

namespace {
/// The most fields one exchange sends through the window (the operator's ghosted fields).
constexpr std::size_t shared_fields = variable_count + 6;
}  // namespace

void Halo::share_memory_with_neighbours() {
  MPI_Comm_split_type(cartesian_, MPI_COMM_TYPE_SHARED, rank_, MPI_INFO_NULL, &machine_);
  MPI_Group everyone, machine;
  MPI_Comm_group(cartesian_, &everyone);
  MPI_Comm_group(machine_, &machine);
  int neighbours[2][2], on_machine[2][2];
  for (int d = 0; d < 2; ++d) {
    neighbours[d][0] = low_[d];
    neighbours[d][1] = high_[d];
  }
  MPI_Group_translate_ranks(everyone, 4, &neighbours[0][0], machine, &on_machine[0][0]);
  MPI_Group_free(&everyone);
  MPI_Group_free(&machine);
  int local = 1;
  for (int d = 0; d < 2; ++d)
    for (int side = 0; side < 2; ++side) local = local && (dims_[d] == 1 || on_machine[d][side] != MPI_UNDEFINED);
  int everywhere = 0;
  MPI_Allreduce(&local, &everywhere, 1, MPI_INT, MPI_LAND, cartesian_);
  if (!everywhere) {
    MPI_Comm_free(&machine_);
    return;
  }
  std::size_t total = 0;
  for (int d = 0; d < 2; ++d) {
    if (dims_[d] == 1) continue;
    for (int r = 0; r < size_; ++r)
      capacity_[d] = std::max(capacity_[d], shared_fields * layer_size(box_, block_of(r), d));
    offset_[d] = total;
    total += 4 * capacity_[d];
  }
  // An MPI without shared windows, or a machine whose shared memory (/dev/shm) is too small
  // for them, leaves every rank with messages instead of ending the run.
  MPI_Comm_set_errhandler(machine_, MPI_ERRORS_RETURN);
  const bool allocated = MPI_Win_allocate_shared(static_cast<MPI_Aint>(total * sizeof(double)), sizeof(double),
                                                 MPI_INFO_NULL, machine_, &mine_, &window_) == MPI_SUCCESS;
  int everyone_allocated = 0, mine = allocated ? 1 : 0;
  MPI_Allreduce(&mine, &everyone_allocated, 1, MPI_INT, MPI_LAND, cartesian_);
  if (!everyone_allocated) {
    if (allocated) MPI_Win_free(&window_);
    window_ = MPI_WIN_NULL;
    mine_ = nullptr;
    capacity_[0] = capacity_[1] = 0;
    MPI_Comm_free(&machine_);
    return;
  }
  MPI_Win_lock_all(MPI_MODE_NOCHECK, window_);
  for (int d = 0; d < 2; ++d)
    for (int side = 0; side < 2; ++side) {
      if (dims_[d] == 1) continue;
      MPI_Aint size = 0;
      int unit = 0;
      double* base = nullptr;
      MPI_Win_shared_query(window_, on_machine[d][side], &size, &unit, &base);
      peers_[d][side] = base;
    }
}

std::pair<int, int> Halo::layout(int ranks) {
  int dims[2] = {0, 0};  // both free for MPI_Dims_create, which orders them px >= py
  MPI_Dims_create(ranks, 2, dims);
  return {dims[1], dims[0]};
}

Halo::~Halo() {
  int finalized = 0;
  MPI_Finalized(&finalized);
  // Freeing a window or a communicator is collective: a rank unwinding from a failure of its
  // own (the root's output, say) would wait there for ranks that never come, instead of
  // reaching main's MPI_Abort. Left allocated, they end with the process.
  if (finalized || std::uncaught_exceptions() > 0) return;
  if (window_ != MPI_WIN_NULL) {
    MPI_Win_unlock_all(window_);
    MPI_Win_free(&window_);
  }
  if (machine_ != MPI_COMM_NULL) MPI_Comm_free(&machine_);
  if (cartesian_ != MPI_COMM_NULL) MPI_Comm_free(&cartesian_);
}

Block Halo::block_of(int rank) const {
  int coords[2] = {0, 0};
  MPI_Cart_coords(cartesian_, rank, 2, coords);
  const auto [i0, nx] = piece(box_.nx, dims_[0], coords[0]);
  const auto [j0, ny] = piece(box_.ny, dims_[1], coords[1]);
  return Block{i0, j0, nx, ny};
}

void Halo::exchange(const std::vector<double*>& fields, bool x_filled) const {
  if (!x_filled || dims_[0] != 1) exchange_direction(0, fields);
  exchange_direction(1, fields);
}

void Halo::exchange_direction(int d, const std::vector<double*>& fields) const {
  const Grid& g = local_;
  const int G = Grid::ghosts;
  const int n = d == 0 ? g.nx : g.ny;
  if (dims_[d] == 1) {  // periodic onto itself: each ghost layer copies the opposite edge
    const std::ptrdiff_t across = n * g.stride(d);
    for (double* field : fields) {
      for_layer(g, d, n - G, [&](std::ptrdiff_t c) { field[c - across] = field[c]; });
      for_layer(g, d, 0, [&](std::ptrdiff_t c) { field[c + across] = field[c]; });
    }
    return;
  }
  if (window_ != MPI_WIN_NULL && fields.size() <= shared_fields) return exchange_shared(d, fields);
  const std::size_t count = layer_size(box_, block_, d) * fields.size();
  for (auto* buffer : {&send_low_, &send_high_, &receive_low_, &receive_high_}) buffer->resize(count);
  const int size = static_cast<int>(count);
  MPI_Request requests[4];
  // Receives posted before the sends, so that the messages need no buffering on arrival.
  MPI_Irecv(receive_low_.data(), size, MPI_DOUBLE, low_[d], tag_upwards, cartesian_, &requests[0]);
  MPI_Irecv(receive_high_.data(), size, MPI_DOUBLE, high_[d], tag_downwards, cartesian_, &requests[1]);
  pack_layers(g, d, 0, fields, send_low_.data());
  pack_layers(g, d, n - G, fields, send_high_.data());
  {
    const Stopwatch timed(communication_seconds_);
    MPI_Isend(send_low_.data(), size, MPI_DOUBLE, low_[d], tag_downwards, cartesian_, &requests[2]);
    MPI_Isend(send_high_.data(), size, MPI_DOUBLE, high_[d], tag_upwards, cartesian_, &requests[3]);
    MPI_Waitall(4, requests, MPI_STATUSES_IGNORE);
  }
  unpack_layers(g, d, -G, fields, receive_low_.data());
  unpack_layers(g, d, n, fields, receive_high_.data());
}

void Halo::exchange_shared(int d, const std::vector<double*>& fields) const {
  const Grid& g = local_;
  const int G = Grid::ghosts;
  const int n = d == 0 ? g.nx : g.ny;
  // Generation `parity` of side s (0: the layers for the low neighbour, 1: for the high one).
  const std::size_t parity = generation_[d]++ % 2;
  const auto part = [&](auto* base, int s) { return base + offset_[d] + (2 * parity + s) * capacity_[d]; };
  pack_layers(g, d, 0, fields, part(mine_, 0));
  pack_layers(g, d, n - G, fields, part(mine_, 1));
  {
    // Each rank tells both neighbours that its layers are in place, and waits for theirs.
    // A generation is rewritten two exchanges later, after the neighbours have said, by
    // their notification of the exchange in between, that they have read it.
    const Stopwatch timed(communication_seconds_);
    MPI_Win_sync(window_);
    MPI_Request requests[4];
    MPI_Irecv(nullptr, 0, MPI_BYTE, low_[d], tag_upwards, cartesian_, &requests[0]);
    MPI_Irecv(nullptr, 0, MPI_BYTE, high_[d], tag_downwards, cartesian_, &requests[1]);
    MPI_Isend(nullptr, 0, MPI_BYTE, low_[d], tag_downwards, cartesian_, &requests[2]);
    MPI_Isend(nullptr, 0, MPI_BYTE, high_[d], tag_upwards, cartesian_, &requests[3]);
    MPI_Waitall(4, requests, MPI_STATUSES_IGNORE);
    MPI_Win_sync(window_);
  }
  // The low neighbour's layers for its high neighbour, and the high one's for its low one.
  unpack_layers(g, d, -G, fields, part(peers_[d][0], 1));
  unpack_layers(g, d, n, fields, part(peers_[d][1], 0));
}

double Halo::sum(double local) const {
  const Stopwatch timed(communication_seconds_);
  double total = 0.0;
  MPI_Allreduce(&local, &total, 1, MPI_DOUBLE, MPI_SUM, cartesian_);
  return total;
}

double Halo::max(double local) const {
  const Stopwatch timed(communication_seconds_);
  double largest = 0.0;
  MPI_Allreduce(&local, &largest, 1, MPI_DOUBLE, MPI_MAX, cartesian_);
  return largest;
}

void Halo::sum(std::vector<double>& values) const {
  const Stopwatch timed(communication_seconds_);
  MPI_Allreduce(MPI_IN_PLACE, values.data(), static_cast<int>(values.size()), MPI_DOUBLE, MPI_SUM,
                cartesian_);
}

std::pair<double, int> Halo::sum_on_machine(double local) const {
  MPI_Comm machine = MPI_COMM_NULL;
  MPI_Comm_split_type(cartesian_, MPI_COMM_TYPE_SHARED, rank_, MPI_INFO_NULL, &machine);
  double total = 0.0;
  int ranks = 0;
  MPI_Allreduce(&local, &total, 1, MPI_DOUBLE, MPI_SUM, machine);
  MPI_Comm_size(machine, &ranks);
  MPI_Comm_free(&machine);
  return {total, ranks};
}

void Halo::broadcast(std::vector<double>& values) const {
  MPI_Bcast(values.data(), static_cast<int>(values.size()), MPI_DOUBLE, 0, cartesian_);
}

bool Halo::agree(std::string& failure) const { return agree(failure, 0); }

bool Halo::agree(std::string& failure, std::int64_t position) const {
  const Stopwatch timed(communication_seconds_);
  // (position, rank) as one key, so that one reduction finds the first failure.
  const std::int64_t none = std::numeric_limits<std::int64_t>::max();
  const std::int64_t mine = failure.empty() ? none : position * size_ + rank_;
  std::int64_t earliest = none;
  MPI_Allreduce(&mine, &earliest, 1, MPI_INT64_T, MPI_MIN, cartesian_);
  if (earliest == none) return true;
  const int first = static_cast<int>(earliest % size_);
  int length = static_cast<int>(failure.size());
  MPI_Bcast(&length, 1, MPI_INT, first, cartesian_);
  failure.resize(static_cast<std::size_t>(length));
  MPI_Bcast(failure.data(), length, MPI_CHAR, first, cartesian_);
  return false;
}

namespace {
/// Calls visit(storage index in g of box column (i0 + i, j0 + j), plane k, m) for every cell
/// of a block, m counting the cells in (k, j, i) order.
template <class Visit> void for_block(const Grid& g, const Block& b, bool offset, Visit visit) {
  std::size_t m = 0;
  const int di = offset ? b.i0 : 0, dj = offset ? b.j0 : 0;
  for (int k = 0; k < g.nz; ++k)
    for (int j = 0; j < b.ny; ++j)
      for (int i = 0; i < b.nx; ++i) visit(g.index(di + i, dj + j, k), m++);
}
}  // namespace

// The gather and the scatter count in columns of every variable (variable_count x nz
// values): MPI's counts and displacements are int, and a box of more than 2^31 values (5
// variables of 430 M cells) would overflow them counted in values, while its columns number
// far fewer. A rank's values are packed in its own order, a whole number of such units.
Halo::ColumnCounts::ColumnCounts(const Halo& halo) : values_per_column(variable_count * halo.box_.nz) {
  MPI_Type_contiguous(values_per_column, MPI_DOUBLE, &type);
  MPI_Type_commit(&type);
  for (int r = 0, at = 0; r < halo.size_; ++r) {
    const Block b = halo.block_of(r);
    counts.push_back(b.nx * b.ny);
    offsets.push_back(at);
    at += counts.back();
  }
}
Halo::ColumnCounts::~ColumnCounts() { MPI_Type_free(&type); }

void Halo::gather(const State& local_state, State& box_state) const {
  const std::size_t cells = local_.interior_cells();
  std::vector<double> mine(variable_count * cells);
  for (int v = 0; v < variable_count; ++v)
    for_block(local_, block_, false, [&](std::ptrdiff_t c, std::size_t m) {
      mine[v * cells + m] = local_state.q[v][c];
    });
  const ColumnCounts columns(*this);
  std::vector<double> all(root() ? box_.interior_cells() * variable_count : 0);
  MPI_Gatherv(mine.data(), block_.nx * block_.ny, columns.type, all.data(), columns.counts.data(),
              columns.offsets.data(), columns.type, 0, cartesian_);
  if (!root()) return;
  if (box_state.size() != box_.size()) box_state.resize(box_.size());
  for (int r = 0; r < size_; ++r) {
    const Block b = block_of(r);
    const std::size_t block_cells = static_cast<std::size_t>(b.nx) * b.ny * box_.nz;
    const double* from = all.data() + columns.first_value(r);
    for (int v = 0; v < variable_count; ++v)
      for_block(box_, b, true, [&](std::ptrdiff_t c, std::size_t m) {
        box_state.q[v][c] = from[v * block_cells + m];
      });
  }
}

void Halo::scatter(const State& box_state, State& local_state) const {
  const ColumnCounts columns(*this);
  std::vector<double> all(root() ? box_.interior_cells() * variable_count : 0);
  if (root()) {
    for (int r = 0; r < size_; ++r) {
      const Block b = block_of(r);
      const std::size_t block_cells = static_cast<std::size_t>(b.nx) * b.ny * box_.nz;
      double* to = all.data() + columns.first_value(r);
      for (int v = 0; v < variable_count; ++v)
        for_block(box_, b, true, [&](std::ptrdiff_t c, std::size_t m) {
          to[v * block_cells + m] = box_state.q[v][c];
        });
    }
  }
  const std::size_t cells = local_.interior_cells();
  std::vector<double> mine(variable_count * cells);
  MPI_Scatterv(all.data(), columns.counts.data(), columns.offsets.data(), columns.type, mine.data(),
               block_.nx * block_.ny, columns.type, 0, cartesian_);
  for (int v = 0; v < variable_count; ++v)
    for_block(local_, block_, false, [&](std::ptrdiff_t c, std::size_t m) {
      local_state.q[v][c] = mine[v * cells + m];
    });
}

}  // namespace shaker::continuum
