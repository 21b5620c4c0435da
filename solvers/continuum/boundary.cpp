// Ghost cells: x and y periodic (3D); z walls that move with the container (mirror state:
// u_z reversed, everything else copied, which gives u_z = 0 and zero normal gradients of
// u_x, u_y and T at the wall), or z periodic for manufactured solutions.
// The primitives and the closure of a ghost are those of the cell it copies (u_z reversed
// at a wall): copied too, not re-evaluated (exactly the same values, since every closure
// value is even in u_z).
// On a decomposed box (halo.hpp) the x and y ghosts come from the neighbouring ranks instead
// of the periodic copy; the z ghosts are filled locally afterwards either way. The conserved
// state's ghosts are never read (every flux takes its neighbours from the primitives and the
// closure), so only these are filled.
#include "continuum/halo.hpp"
#include "continuum/operator.hpp"

namespace shaker::continuum {

namespace {
template <class Body> void loop(const Grid& g, int begin, int end, Body body) {
  if (g.threaded()) {
#pragma omp parallel for schedule(static)
    for (int m = begin; m < end; ++m) body(m);
  } else {
    for (int m = begin; m < end; ++m) body(m);
  }
}

/// Calls copy(to, from, reverse_z) for every y ghost of the interior planes, x ghosts
/// included (filled before, by the closure's rows), so that every source cell is filled.
template <class Copy> void for_each_periodic_y_ghost(const Grid& g, Copy copy) {
  const int G = Grid::ghosts;
  loop(g, 0, g.nz, [&](int k) {
    for (int i = -G; i < g.nx + G; ++i)
      for (int m = 1; m <= G; ++m) {
        copy(g.index(i, -m, k), g.index(i, g.ny - m, k), false);
        copy(g.index(i, g.ny - 1 + m, k), g.index(i, m - 1, k), false);
      }
  });
}

/// Calls copy(to, from, reverse_z) for every z ghost, x and y ghosts included (so after them).
/// Ghosts are disjoint and each is a copy, so the threads' order does not matter.
template <class Copy> void for_each_z_ghost(const Grid& g, Copy copy) {
  const int G = Grid::ghosts;
  const int gxy = g.ghosts_xy();
  const bool walls = g.z_boundary == ZBoundary::walls;
  loop(g, -gxy, g.ny + gxy, [&](int j) {
    for (int i = -gxy; i < g.nx + gxy; ++i)
      for (int m = 1; m <= G; ++m) {
        if (walls) {
          copy(g.index(i, j, -m), g.index(i, j, m - 1), true);
          copy(g.index(i, j, g.nz - 1 + m), g.index(i, j, g.nz - m), true);
        } else {
          copy(g.index(i, j, -m), g.index(i, j, g.nz - m), false);
          copy(g.index(i, j, g.nz - 1 + m), g.index(i, j, m - 1), false);
        }
      }
  });
}

/// Every ghost of `fields`: x (unless the rows filled them) and y from the halo, or y by
/// the periodic copy, then z.
template <class Copy>
void fill(const Grid& g, const Halo* halo, const std::vector<double*>& fields, bool x_filled, Copy copy) {
  if (halo)
    halo->exchange(fields, x_filled);
  else if (g.dimension == 3)
    for_each_periodic_y_ghost(g, copy);
  for_each_z_ghost(g, copy);
}
}  // namespace

// The fluxes read the primitives and the closure beside each cell; the collisional loss
// only in the cell itself (sources.cpp), so its ghosts are not filled.
std::array<std::vector<double>*, variable_count + 6> Operator::ghosted_fields() {
  return {&w_[0],       &w_[1],       &w_[2],         &w_[3],      &w_[4],          &closure_.p,
          &closure_.c,  &closure_.chi, &closure_.mu,  &closure_.lambda, &closure_.kappa};
}

bool Operator::x_ghosts_by_rows() const {
  return grid_.dimension == 3 && (!halo_ || halo_->ranks_along(0) == 1);
}

void Operator::copy_row_to_x_ghosts(std::ptrdiff_t first) {
  const int nx = grid_.nx;
  for (std::vector<double>* field : ghosted_fields()) {
    double* row = field->data() + first;
    for (int m = 1; m <= Grid::ghosts; ++m) {
      row[-m] = row[nx - m];
      row[nx - 1 + m] = row[m - 1];
    }
  }
}

void Operator::copy_closure_to_ghosts() {
  const auto ghosted = ghosted_fields();
  std::vector<double*> fields;
  if (halo_)
    for (auto* v : ghosted) fields.push_back(v->data());
  fill(grid_, halo_.get(), fields, x_ghosts_by_rows(), [&](std::ptrdiff_t to, std::ptrdiff_t from, bool reverse_z) {
    for (auto* v : ghosted) (*v)[to] = (*v)[from];
    if (reverse_z) w_[3][to] = -w_[3][from];
  });
}

}  // namespace shaker::continuum
