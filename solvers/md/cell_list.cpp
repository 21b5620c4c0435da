#include "md/cell_list.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "common/errors.hpp"

namespace shaker::md {

void CellList::build(const Geometry& g, std::size_t n) {
  width_ = g.width;
  height_ = g.height;
  periodic_z_ = g.periodic_z;
  nx_ = ny_ = static_cast<int>(std::floor(g.width));
  const int rows = std::max(1, static_cast<int>(std::floor(g.height)));
  nz_ = rows;
  if (!periodic_z_ && g.gravity > 0.0) {
    // A tall shaker box is almost empty high up (the base case: 200 rows for a layer about
    // 10 thick), and a dense grid there would cost more memory than the particles. Above the
    // height that holds every particle eight times over (plus the plate's stroke) one open row
    // reaches to the ceiling; its edge is still >= sigma, so the 27-cell stencil stays exact
    // (only slower if many particles fly that high).
    const double column = static_cast<double>(n) / (static_cast<double>(nx_) * nx_);
    const double enough = g.plate_top() + 8.0 * column + 3.0;
    if (enough < rows) nz_ = std::max(3, static_cast<int>(std::ceil(enough)));
  }
  if (nx_ < 3 || (periodic_z_ && nz_ < 3))
    throw InputError(fmt::format(
        "md.box_width = {} (and the periodic height {}) must be at least 3 sigma: the cell "
        "list needs three cells across the periodic box", g.width, g.height));
  ex_ = g.width / nx_;
  ey_ = g.width / ny_;
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

}  // namespace shaker::md
