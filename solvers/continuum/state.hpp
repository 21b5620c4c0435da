#pragma once
// Conserved variables per cell (structure of arrays): number density n (= mass density,
// particle mass 1), momentum n u, and total energy E = (3/2) n T + (1/2) n |u|^2.
#include <algorithm>
#include <array>
#include <cstddef>
#include <vector>

namespace shaker::continuum {

enum Variable : int { density = 0, momentum_x, momentum_y, momentum_z, energy, variable_count };

struct State {
  std::array<std::vector<double>, variable_count> q;
  void resize(std::size_t cells) {
    for (auto& v : q) v.assign(cells, 0.0);
  }
  std::size_t size() const { return q[0].size(); }
};

struct Primitive {
  double n = 0, ux = 0, uy = 0, uz = 0, T = 0;
};

inline Primitive to_primitive(const State& s, std::size_t c) {
  Primitive w;
  w.n = s.q[density][c];
  const double inv = 1.0 / w.n;
  w.ux = s.q[momentum_x][c] * inv;
  w.uy = s.q[momentum_y][c] * inv;
  w.uz = s.q[momentum_z][c] * inv;
  const double kinetic = 0.5 * (s.q[momentum_x][c] * w.ux + s.q[momentum_y][c] * w.uy +
                                s.q[momentum_z][c] * w.uz);
  // E - kinetic loses digits in fast, cold, dilute cells: a round-off negative is zero.
  w.T = std::max(0.0, (s.q[energy][c] - kinetic) * inv / 1.5);
  return w;
}

/// to_primitive of the cells first .. first + length - 1 into w (n, ux, uy, uz, T), adjacent
/// cells at once, per cell bit for bit to_primitive (primitives.cpp).
void to_primitives(const State& U, std::array<std::vector<double>, variable_count>& w, std::ptrdiff_t first,
                   int length);

inline void store_primitive(State& s, std::size_t c, const Primitive& w) {
  s.q[density][c] = w.n;
  s.q[momentum_x][c] = w.n * w.ux;
  s.q[momentum_y][c] = w.n * w.uy;
  s.q[momentum_z][c] = w.n * w.uz;
  s.q[energy][c] = w.n * (1.5 * w.T + 0.5 * (w.ux * w.ux + w.uy * w.uy + w.uz * w.uz));
}

}  // namespace shaker::continuum
