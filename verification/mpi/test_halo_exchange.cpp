// The halo exchange of the decomposed 3D box, run under `mpirun -np P` (P = 2, 3, 4): every x
// and y ghost of every rank's block, corners included, must hold the value of the periodic
// box's cell it stands for, through the shared-memory window and through messages alike, for
// the operator's 11 fields, one field (the implicit diffusion's) and more fields than the
// window holds (which fall back to messages), over repeated exchanges (the window alternates
// two generations); and, launched without shared windows, the fallback to messages.
#include <gtest/gtest.h>
#include <mpi.h>

#include <cmath>
#include <string>
#include <vector>

#include "common/ranks.hpp"
#include "continuum/halo.hpp"

namespace {

using shaker::continuum::Grid;
using shaker::continuum::Halo;
using shaker::continuum::HaloTransport;

/// The value of box cell (i, j, k) (periodic in i and j) in field f at exchange `round`.
double box_value(const Grid& box, int f, int round, int i, int j, int k) {
  const int pi = (i % box.nx + box.nx) % box.nx, pj = (j % box.ny + box.ny) % box.ny;
  return 1e6 * round + 1e4 * f + (static_cast<double>(k) * box.ny + pj) * box.nx + pi;
}

/// The first wrong ghost after `rounds` exchanges of `field_count` fields, or "".
std::string first_wrong_ghost(const Halo& halo, int field_count, int rounds) {
  const Grid& g = halo.local();
  const Grid& box = halo.box();
  const int i0 = halo.block().i0, j0 = halo.block().j0, G = Grid::ghosts;
  std::vector<std::vector<double>> fields(field_count, std::vector<double>(g.size()));
  std::vector<double*> pointers;
  for (auto& field : fields) pointers.push_back(field.data());
  for (int round = 0; round < rounds; ++round) {
    for (int f = 0; f < field_count; ++f)
      for (int k = 0; k < g.nz; ++k)
        for (int j = -G; j < g.ny + G; ++j)
          for (int i = -G; i < g.nx + G; ++i) {
            const bool interior = i >= 0 && i < g.nx && j >= 0 && j < g.ny;
            fields[f][g.index(i, j, k)] = interior ? box_value(box, f, round, i0 + i, j0 + j, k) : std::nan("");
          }
    halo.exchange(pointers);
    for (int f = 0; f < field_count; ++f)
      for (int k = 0; k < g.nz; ++k)
        for (int j = -G; j < g.ny + G; ++j)
          for (int i = -G; i < g.nx + G; ++i) {
            const double expected = box_value(box, f, round, i0 + i, j0 + j, k);
            if (fields[f][g.index(i, j, k)] != expected)
              return "rank " + std::to_string(halo.rank()) + ", round " + std::to_string(round) + ", field " +
                     std::to_string(f) + ", cell (" + std::to_string(i) + ", " + std::to_string(j) + ", " +
                     std::to_string(k) + "): " + std::to_string(fields[f][g.index(i, j, k)]) + ", expected " +
                     std::to_string(expected);
          }
  }
  return "";
}

Grid box_of(int nx, int ny) {
  Grid box;
  box.dimension = 3;
  box.nx = nx;
  box.ny = ny;
  box.nz = 3;
  return box;
}

/// Set by --expect-messages: the launch offers no shared windows (`--mca osc ^sm`), so the
/// automatic transport must fall back to messages.
bool windows_unavailable = false;

class HaloExchange : public testing::TestWithParam<HaloTransport> {};

TEST_P(HaloExchange, EveryGhostHoldsItsPeriodicCell) {
  const int ranks = shaker::Ranks::world().size();
  ASSERT_GE(ranks, 2) << "run under mpirun -np 2 or more";
  for (const auto& [nx, ny] : {std::pair{7, 9}, std::pair{12, 10}}) {
    const Halo halo(box_of(nx, ny), ranks, GetParam());
    // A single machine: automatic shares memory (unless the launch has no shared windows),
    // messages does not.
    EXPECT_EQ(halo.shares_memory(), GetParam() == HaloTransport::automatic && !windows_unavailable);
    for (const int field_count : {11, 1, 12})
      EXPECT_EQ(first_wrong_ghost(halo, field_count, 5), "")
          << nx << " x " << ny << " cells, " << field_count << " fields";
  }
}

INSTANTIATE_TEST_SUITE_P(Transports, HaloExchange, testing::Values(HaloTransport::automatic, HaloTransport::messages),
                         [](const auto& transport) {
                           return transport.param == HaloTransport::automatic ? std::string("Automatic")
                                                                         : std::string("Messages");
                         });

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  for (int a = 1; a < argc; ++a) windows_unavailable = windows_unavailable || std::string(argv[a]) == "--expect-messages";
  shaker::Ranks::world();  // MPI_Init under the launcher
  const int failed = RUN_ALL_TESTS();
  int any_failed = 0;
  MPI_Allreduce(&failed, &any_failed, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  shaker::Ranks::finalize();
  return any_failed;
}
