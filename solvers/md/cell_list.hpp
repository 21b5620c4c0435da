#pragma once
// Cell list with cells of edge >= sigma: a particle can only meet particles in its own and
// the 26 surrounding cells before it leaves its cell (the cell crossing is itself an event).
// Doubly linked lists per cell keep insertion and removal O(1) without allocation.
#include <cstdint>
#include <string>
#include <vector>

#include "md/geometry.hpp"
#include "md/particles.hpp"
#include "md/prefetch.hpp"

namespace shaker::md {

class CellList {
 public:
  /// Grid for the geometry; n particles, all unassigned. Throws InputError if the box is
  /// narrower than three cells (the neighbour stencil would see a cell twice).
  void build(const Geometry& geometry, std::size_t n);

  int cell_of(const Vec3& r) const;
  /// What is wrong with lists loaded from a checkpoint (empty if nothing): every particle in
  /// exactly one list, links in both directions, and each particle's position at its local
  /// time inside its cell (within `tolerance`). A damaged list would make the run miss
  /// collisions without any sign.
  std::string inconsistency(const std::vector<Particle>& particles, double tolerance) const;
  void insert(std::int32_t particle, int cell);
  void remove(std::int32_t particle);
  int cell(std::int32_t particle) const { return cell_[particle]; }

  int nx() const { return nx_; }
  int ny() const { return ny_; }
  int nz() const { return nz_; }
  int ix(int c) const { return c % nx_; }
  int iy(int c) const { return (c / nx_) % ny_; }
  int iz(int c) const { return c / (nx_ * ny_); }
  int index(int x, int y, int z) const { return (z * ny_ + y) * nx_ + x; }
  double edge_x() const { return ex_; }
  double edge_y() const { return ey_; }
  double edge_z() const { return ez_; }

  /// Calls f(j, shift) for every particle j in the 27 cells around cell c; shift is the
  /// periodic image offset to add to j's position.
  template <class F> void for_each_neighbor(int c, F&& f) const {
    for_each_neighbor_cell(c, [&](int cell, const Vec3& shift) {
      for (std::int32_t j = head_[cell]; j >= 0; j = next_[j]) f(j, shift);
    });
  }
  /// Calls f(cell, shift) for the 27 cells around cell c, in the order for_each_neighbor
  /// visits their particles.
  template <class F> void for_each_neighbor_cell(int c, F&& f) const {
    const int cx = ix(c), cy = iy(c), cz = iz(c);
    if (cx > 0 && cx < nx_ - 1 && cy > 0 && cy < ny_ - 1 && cz > 0 && cz < nz_ - 1) {
      // Away from the box faces no index wraps and no image shift applies; the cells are
      // visited in the same order as for_each_cell_in_block visits them.
      const Vec3 none{};
      const int plane = nx_ * ny_;
      for (int dz = -plane; dz <= plane; dz += plane)  // the nine rows are far apart in memory
        for (int dy = -nx_; dy <= nx_; dy += nx_) prefetch(&head_[c + dz + dy - 1]);
      for (int dz = -plane; dz <= plane; dz += plane)
        for (int dy = -nx_; dy <= nx_; dy += nx_)
          for (int dx = -1; dx <= 1; ++dx) f(c + dz + dy + dx, none);
      return;
    }
    for_each_cell_in_block(c, -1, 1, -1, 1, -1, 1, f);
  }
  /// Prefetches the heads of the 27 cells around cell c (nine rows of three, far apart in
  /// memory): a hint only, nothing is read.
  void prefetch_block(int c) const {
    const int cx = ix(c), cy = iy(c), cz = iz(c);
    if (cx > 0 && cx < nx_ - 1 && cy > 0 && cy < ny_ - 1 && cz > 0 && cz < nz_ - 1) {
      const int plane = nx_ * ny_;
      for (int dz = -plane; dz <= plane; dz += plane)
        for (int dy = -nx_; dy <= nx_; dy += nx_) {
          prefetch(&head_[static_cast<std::size_t>(c + dz + dy - 1)]);
          prefetch(&head_[static_cast<std::size_t>(c + dz + dy + 1)]);
        }
      return;
    }
    for_each_cell_in_block(c, -1, 1, -1, 1, -1, 1, [&](int cell, const Vec3&) {
      prefetch(&head_[static_cast<std::size_t>(cell)]);
    });
  }
  /// Prefetches the list links of particle p (a hint: nothing is read).
  void prefetch_links(std::int32_t p) const {
    prefetch(&prev_[static_cast<std::size_t>(p)]);
    prefetch(&next_[static_cast<std::size_t>(p)]);
  }
  /// The cell next to c across its face `direction` (2 axis + 1 if upwards), wrapping
  /// periodically (or c itself beyond a wall: a hint for prefetching only).
  int neighbor_cell(int c, int direction) const {
    int x = ix(c), y = iy(c), z = iz(c);
    const int step = (direction & 1) ? 1 : -1;
    auto move = [step](int& u, int count) { u += step; u = u < 0 ? u + count : (u >= count ? u - count : u); };
    switch (direction / 2) {
      case 0: move(x, nx_); break;
      case 1: move(y, ny_); break;
      default: move(z, nz_); break;
    }
    return index(x, y, z);
  }
  /// Calls f(cell, shift) for the 9 cells that became neighbours when a particle entered cell c
  /// by a crossing along `axis` (0, 1, 2) in direction `step` (+1 or -1).
  template <class F> void for_each_cell_in_new_face(int c, int axis, int step, F&& f) const {
    const int lo[3] = {axis == 0 ? step : -1, axis == 1 ? step : -1, axis == 2 ? step : -1};
    const int hi[3] = {axis == 0 ? step : 1, axis == 1 ? step : 1, axis == 2 ? step : 1};
    for_each_cell_in_block(c, lo[0], hi[0], lo[1], hi[1], lo[2], hi[2], f);
  }
  /// Calls f(cell, shift) for the cells c + (dx, dy, dz) with offsets in the given ranges
  /// (z outermost, x innermost); cells beyond a non-periodic face are skipped.
  template <class F>
  void for_each_cell_in_block(int c, int x0, int x1, int y0, int y1, int z0, int z1, F&& f) const;

  // Raw lists, stored in checkpoints so that a restart visits neighbours in the same order.
  std::vector<std::int32_t> head_, next_, prev_, cell_;

 private:
  int nx_ = 0, ny_ = 0, nz_ = 0;
  double ex_ = 1.0, ey_ = 1.0, ez_ = 1.0;
  double width_ = 0.0, depth_ = 0.0, height_ = 0.0;
  bool periodic_z_ = false;
};

template <class F>
void CellList::for_each_cell_in_block(int c, int x0, int x1, int y0, int y1, int z0, int z1, F&& f) const {
  const int cx = ix(c), cy = iy(c), cz = iz(c);
  for (int dz = z0; dz <= z1; ++dz) {
    int z = cz + dz;
    double sz = 0.0;
    if (z < 0 || z >= nz_) {
      if (!periodic_z_) continue;
      sz = z < 0 ? -height_ : height_;
      z = z < 0 ? z + nz_ : z - nz_;
    }
    for (int dy = y0; dy <= y1; ++dy) {
      int y = cy + dy;
      double sy = 0.0;
      if (y < 0) { y += ny_; sy = -depth_; }
      else if (y >= ny_) { y -= ny_; sy = depth_; }
      for (int dx = x0; dx <= x1; ++dx) {
        int x = cx + dx;
        double sx = 0.0;
        if (x < 0) { x += nx_; sx = -width_; }
        else if (x >= nx_) { x -= nx_; sx = width_; }
        f(index(x, y, z), Vec3{sx, sy, sz});
      }
    }
  }
}

}  // namespace shaker::md
