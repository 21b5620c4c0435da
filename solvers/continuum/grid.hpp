#pragma once
// Uniform finite-volume grid with two ghost layers. The same grid serves the 1D vertical
// column (only z resolved, fields per unit plate area) and the 3D box (periodic x, y): the
// dimension is a run-time parameter of every kernel, never a second copy of the solver.
#include <cstddef>

namespace shaker::continuum {

enum class ZBoundary { walls, periodic };  ///< periodic z exists for manufactured solutions

struct Grid {
  static constexpr int ghosts = 2;  ///< enough for limited MUSCL reconstruction
  int dimension = 1;                ///< 1 or 3
  int nx = 1, ny = 1, nz = 1;       ///< interior cells per direction
  double h = 0.1;                   ///< cell size, the same in every direction
  ZBoundary z_boundary = ZBoundary::walls;

  int ghosts_xy() const { return dimension == 3 ? ghosts : 0; }
  std::ptrdiff_t stride_y() const { return nx + 2 * ghosts_xy(); }
  std::ptrdiff_t stride_z() const { return stride_y() * (ny + 2 * ghosts_xy()); }
  std::ptrdiff_t stride(int direction) const {
    return direction == 0 ? 1 : direction == 1 ? stride_y() : stride_z();
  }
  std::size_t size() const { return static_cast<std::size_t>(stride_z() * (nz + 2 * ghosts)); }
  std::size_t interior_cells() const { return static_cast<std::size_t>(nx) * ny * nz; }
  /// Storage index of interior cell (i, j, k); ghosts have indices -ghosts .. n + ghosts - 1.
  std::ptrdiff_t index(int i, int j, int k) const {
    return (i + ghosts_xy()) + stride_y() * (j + ghosts_xy()) + stride_z() * (k + ghosts);
  }
  /// Directions that carry fluxes: z only in 1D, x, y and z in 3D.
  int first_direction() const { return dimension == 3 ? 0 : 2; }
  double center(int i) const { return (i + 0.5) * h; }
  /// Volume of a cell; in 1D the column has unit cross section, so amounts are per unit area.
  double cell_volume() const { return dimension == 3 ? h * h * h : h; }
  double height() const { return nz * h; }
  /// The interior cells as contiguous runs of storage: one run in 1D (no x, y ghosts), one
  /// row of nx per (j, k) in 3D. Loops over runs instead of (i, j, k) let a 1D column be a
  /// single loop of nz cells.
  int interior_rows() const { return dimension == 3 ? ny * nz : 1; }
  /// First storage index of run `row` (0 <= row < interior_rows()); its cells are
  /// row_start(row) .. row_start(row) + row_length() - 1.
  std::ptrdiff_t row_start(int row) const {
    return dimension == 3 ? index(0, row % ny, row / ny) : index(0, 0, 0);
  }
  int row_length() const { return dimension == 3 ? nx : nx * ny * nz; }
  /// Worth sharing between OpenMP threads: a 3D box of more than 4096 cells. A 1D column never
  /// is (one run of cells; even entering a region whose `if` is false costs a runtime call).
  bool threaded() const { return dimension == 3 && interior_cells() > 4096; }
};

/// The solver's working set per interior cell: the 3D solver's measured 579 B
/// (reports/benchmarks.md) rounded up. A run checks its memory before it allocates
/// (run_continuum.cpp), per machine when decomposed.
inline constexpr double solver_bytes_per_cell = 600.0;

/// A grid of cell size h over [0, width] x [0, depth] x [0, height] (width and depth unused
/// in 1D); throws InputError naming the key when the cell size does not divide the box, or
/// when the grid split evenly over `processes` would not fit the available memory.
Grid make_grid(int dimension, double width, double depth, double height, double h, int processes = 1);

}  // namespace shaker::continuum
