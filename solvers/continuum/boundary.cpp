// Ghost cells: x and y periodic (3D); z walls that move with the container (mirror state:
// u_z reversed, everything else copied, which gives u_z = 0 and zero normal gradients of
// u_x, u_y and T at the wall), or z periodic for manufactured solutions.
#include "continuum/operator.hpp"

namespace shaker::continuum {

namespace {
void copy_cell(State& U, std::ptrdiff_t to, std::ptrdiff_t from, bool reverse_z) {
  for (int v = 0; v < variable_count; ++v) U.q[v][to] = U.q[v][from];
  if (reverse_z) U.q[momentum_z][to] = -U.q[momentum_z][from];
}
}  // namespace

void Operator::fill_ghosts(State& U) const {
  const Grid& g = grid_;
  const int G = Grid::ghosts;
  if (g.dimension == 3) {
    for (int k = 0; k < g.nz; ++k)
      for (int j = 0; j < g.ny; ++j)
        for (int m = 1; m <= G; ++m) {
          copy_cell(U, g.index(-m, j, k), g.index(g.nx - m, j, k), false);
          copy_cell(U, g.index(g.nx - 1 + m, j, k), g.index(m - 1, j, k), false);
        }
    for (int k = 0; k < g.nz; ++k)
      for (int i = -G; i < g.nx + G; ++i)
        for (int m = 1; m <= G; ++m) {
          copy_cell(U, g.index(i, -m, k), g.index(i, g.ny - m, k), false);
          copy_cell(U, g.index(i, g.ny - 1 + m, k), g.index(i, m - 1, k), false);
        }
  }
  const int gxy = g.ghosts_xy();
  const bool walls = g.z_boundary == ZBoundary::walls;
  for (int j = -gxy; j < g.ny + gxy; ++j)
    for (int i = -gxy; i < g.nx + gxy; ++i)
      for (int m = 1; m <= G; ++m) {
        if (walls) {
          copy_cell(U, g.index(i, j, -m), g.index(i, j, m - 1), true);
          copy_cell(U, g.index(i, j, g.nz - 1 + m), g.index(i, j, g.nz - m), true);
        } else {
          copy_cell(U, g.index(i, j, -m), g.index(i, j, g.nz - m), false);
          copy_cell(U, g.index(i, j, g.nz - 1 + m), g.index(i, j, m - 1), false);
        }
      }
}

}  // namespace shaker::continuum
