#include "md/cell_list.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "common/errors.hpp"

namespace shaker::md {

void CellList::build(const Geometry& g, std::size_t n) {
  width_ = g.width;
  depth_ = g.depth;
  height_ = g.height;
  periodic_z_ = g.periodic_z;
  nx_ = static_cast<int>(std::floor(g.width));
  ny_ = static_cast<int>(std::floor(g.depth));
  const int rows = std::max(1, static_cast<int>(std::floor(g.height)));
  nz_ = rows;
  if (!periodic_z_ && g.gravity > 0.0) {
    // A tall shaker box is almost empty high up (the base case: 200 rows for a layer about
    // 10 thick), and a dense grid there would cost more memory than the particles. Above the
    // height that holds every particle eight times over (plus the plate's stroke) one open row
    // reaches to the ceiling; its edge is still >= sigma, so the 27-cell stencil stays exact
    // (only slower if many particles fly that high).
    const double column = static_cast<double>(n) / (static_cast<double>(nx_) * ny_);
    const double enough = g.plate_top() + 8.0 * column + 3.0;
    if (enough < rows) nz_ = std::max(3, static_cast<int>(std::ceil(enough)));
  }
  if (nx_ < 3 || ny_ < 3 || (periodic_z_ && nz_ < 3))
    throw InputError(fmt::format(
        "md.box_width = {}, md.box_depth = {} (and the periodic height {}) must be at least 3 "
        "sigma: the cell list needs three cells across the periodic box", g.width, g.depth, g.height));
  ex_ = g.width / nx_;
  ey_ = g.depth / ny_;
  ez_ = g.height / rows;  // the open top row (if any) spans [(nz_ - 1) ez_, height]
  head_.assign(static_cast<std::size_t>(nx_) * ny_ * nz_, -1);
  next_.assign(n, -1);
  prev_.assign(n, -1);
  cell_.assign(n, -1);
}

int CellList::cell_of(const Vec3& r) const {
  auto clamp_index = [](double u, double edge, int count) {
    return std::clamp(static_cast<int>(std::floor(u / edge)), 0, count - 1);
  };
  return index(clamp_index(r.x, ex_, nx_), clamp_index(r.y, ey_, ny_), clamp_index(r.z, ez_, nz_));
}

void CellList::insert(std::int32_t p, int c) {
  cell_[p] = c;
  prev_[p] = -1;
  next_[p] = head_[c];
  if (head_[c] >= 0) prev_[head_[c]] = p;
  head_[c] = p;
}

void CellList::remove(std::int32_t p) {
  const int c = cell_[p];
  if (prev_[p] >= 0) next_[prev_[p]] = next_[p];
  else head_[c] = next_[p];
  if (next_[p] >= 0) prev_[next_[p]] = prev_[p];
  cell_[p] = -1;
}

std::string CellList::inconsistency(const std::vector<Particle>& particles, double tolerance) const {
  const auto n = static_cast<std::int32_t>(particles.size());
  if (next_.size() != particles.size() || prev_.size() != particles.size() || cell_.size() != particles.size())
    return fmt::format("{} particles but lists for {}", n, cell_.size());
  std::vector<bool> listed(particles.size(), false);
  const auto cells = static_cast<int>(head_.size());
  for (int c = 0; c < cells; ++c) {
    std::int32_t before = -1;
    for (std::int32_t j = head_[static_cast<std::size_t>(c)]; j >= 0; before = j, j = next_[static_cast<std::size_t>(j)]) {
      if (j >= n) return fmt::format("cell {} lists particle {}; allowed 0 to {}", c, j, n - 1);
      const auto k = static_cast<std::size_t>(j);
      if (listed[k]) return fmt::format("particle {} is listed twice", j);
      listed[k] = true;
      if (cell_[k] != c) return fmt::format("particle {} is listed in cell {} but its cell is {}", j, c, cell_[k]);
      if (prev_[k] != before) return fmt::format("particle {}: backward link {}, expected {}", j, prev_[k], before);
    }
  }
  for (std::int32_t i = 0; i < n; ++i)
    if (!listed[static_cast<std::size_t>(i)]) return fmt::format("particle {} is in no cell list", i);
  // The lowest row reaches down to the plate and the open top row up to the ceiling.
  auto outside = [tolerance](double u, int index, double edge, int count, bool open_ends) {
    const double lo = (open_ends && index == 0) ? -INFINITY : index * edge - tolerance;
    const double hi = (open_ends && index == count - 1) ? INFINITY : (index + 1) * edge + tolerance;
    return !(u >= lo && u <= hi);
  };
  for (std::int32_t i = 0; i < n; ++i) {
    const Vec3& r = particles[static_cast<std::size_t>(i)].r;
    const int c = cell_[static_cast<std::size_t>(i)];
    if (outside(r.x, ix(c), ex_, nx_, false) || outside(r.y, iy(c), ey_, ny_, false) ||
        outside(r.z, iz(c), ez_, nz_, !periodic_z_))
      return fmt::format("particle {} at ({}, {}, {}) is listed in cell ({}, {}, {}) of edges {:.6g} x {:.6g} x {:.6g}, "
                         "which does not contain it", i, r.x, r.y, r.z, ix(c), iy(c), iz(c), ex_, ey_, ez_);
  }
  return {};
}

}  // namespace shaker::md
