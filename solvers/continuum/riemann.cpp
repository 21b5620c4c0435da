// Inviscid fluxes: limited MUSCL reconstruction of (n, u, T, p, c) to both sides of each face
// (each cell's slopes computed once, for both of its faces) and an approximate Riemann solver. Reconstructed are n, u, p, chi = p / (n T) and c; the
// face temperature is p / (n chi), so pressure and internal energy stay consistent across a
// contact (no pressure wiggles), and the equation of state is not re-evaluated at faces
// (second order all the same, two fewer closure evaluations per face). Pressureless runs
// reconstruct T itself. At wall faces only the normal momentum flux
// (the wall pressure) survives; mass, energy and tangential momentum fluxes are exactly zero,
// so mass is conserved to round-off.
#include <algorithm>
#include <type_traits>
#include <utility>

#include "continuum/reconstruct.hpp"
#include "continuum/riemann.hpp"

namespace shaker::continuum {

namespace {

/// The cells of one direction as pencils: base index of each pencil and the step along it.
struct Pencils {
  int count_a, count_b, length;  ///< pencils = count_a x count_b, `length` cells each
  std::ptrdiff_t base(const Grid& g, int d, int a, int b) const {
    return d == 0 ? g.index(0, a, b) : d == 1 ? g.index(a, 0, b) : g.index(a, b, 0);
  }
};
Pencils pencils_of(const Grid& g, int d) {
  if (d == 0) return {g.ny, g.nz, g.nx};
  if (d == 1) return {g.nx, g.nz, g.ny};
  return {g.nx, g.ny, g.nz};
}

/// Faces handled per block of a pencil: the block's face states and fluxes stay in L1.
constexpr int face_block = 64;

template <Limiter L, RiemannSolver R>
void inviscid_fluxes(const Grid& g, const std::array<std::vector<double>, variable_count>& w,
                     const Operator::Closure& closure, bool pressureful, State& dUdt) {
  const double inv_h = 1.0 / g.h;
  const bool pressure = pressureful;
  const double* fields[7] = {w[0].data(),  w[1].data(),
                             w[2].data(),  w[3].data(),
                             pressure ? closure.p.data() : w[4].data(),
                             closure.chi.data(), closure.c.data()};
  // First-order face state: n, u, T, p, c of the cell itself.
  const auto cell_state = [&](std::ptrdiff_t c, double* state) {
    for (int v = 0; v < 5; ++v) state[v] = w[v][c];
    state[5] = closure.p[c];
    state[6] = closure.c[c];
  };
  // Characteristic limiting of (n, u_n, p): the differences are projected on the acoustic
  // and entropy waves of the primitive Euler system (valid for any equation of state, with c
  // the isentropic sound speed, which model::sound_speed is), limited wave by wave and
  // projected back. Component-wise limiting of n, u and p lets the waves of a strong
  // Riemann problem interact in the slopes and leaves oscillations of a few per cent behind
  // shocks. A face value that comes out non-positive keeps the component-wise one.
  const double* fn = w[0].data();
  const double* fp = closure.p.data();
  const double* fc = closure.c.data();
  // minus[v][slot], plus[v][slot]: face states at the low and high face of the block's cell q
  // of pencil `lane`, slot = q W + lane, for W pencils at once (W = 2: two pencils side by side
  // in x, whose cells are adjacent in storage).
  using FaceStates = double[7][(face_block + 1) * 2];
  // S = double: cell c; S = Pair: cells c and c + 1, either of a contiguous pencil (s = 1,
  // slots q and q + 1) or of two pencils side by side (W = 2, the two lanes of cell q), every
  // lane doing the scalar arithmetic, the early returns of the scalar code as a mask.
  const auto characteristic = [&](std::ptrdiff_t c, std::ptrdiff_t s, int un, int q,
                                  FaceStates& minus, FaceStates& plus, auto lanes) {
    using S = decltype(lanes);
    const auto at = [](const double* x) { return load_lanes<S>(x); };
    const double* u = w[un].data();
    const S n0 = at(fn + c), c0 = at(fc + c), p0 = at(fp + c), u0 = at(u + c);
    const S impedance = n0 * c0, inv_c2 = 1.0 / (c0 * c0);
    const S dn_b = n0 - at(fn + c - s), dn_f = at(fn + c + s) - n0;
    const S du_b = u0 - at(u + c - s), du_f = at(u + c + s) - u0;
    const S dp_b = p0 - at(fp + c - s), dp_f = at(fp + c + s) - p0;
    const S w1 = limited_slope<L>(dp_b - impedance * du_b, dp_f - impedance * du_f);
    const S w2 = limited_slope<L>(dn_b - dp_b * inv_c2, dn_f - dp_f * inv_c2);
    const S w3 = limited_slope<L>(dp_b + impedance * du_b, dp_f + impedance * du_f);
    const S dp = 0.5 * (w1 + w3), du = 0.5 * (w3 - w1) / impedance, dn = w2 + dp * inv_c2;
    const S n_plus = n0 + 0.5 * dn, p_plus = p0 + 0.5 * dp;
    const S n_minus = n0 - 0.5 * dn, p_minus = p0 - 0.5 * dp;
    // (no sound speed, or a face value that is not positive: keep the component-wise values)
    const auto keep = (c0 > 0.0) & (n_plus > 0.0) & (p_plus > 0.0) & (n_minus > 0.0) & (p_minus > 0.0);
    store_lanes_where(keep, &plus[0][q], n_plus);
    store_lanes_where(keep, &plus[un][q], u0 + 0.5 * du);
    store_lanes_where(keep, &plus[4][q], p_plus);
    store_lanes_where(keep, &minus[0][q], n_minus);
    store_lanes_where(keep, &minus[un][q], u0 - 0.5 * du);
    store_lanes_where(keep, &minus[4][q], p_minus);
  };
  for (int d = g.first_direction(); d < 3; ++d) {
    const std::ptrdiff_t s = g.stride(d);
    const int un_index = 1 + d;
    const Pencils P = pencils_of(g, d);
    const bool walls = d == 2 && g.z_boundary == ZBoundary::walls;
    const int normal = momentum_x + d;
    const int tangential1 = momentum_x + (d + 1) % 3, tangential2 = momentum_x + (d + 2) % 3;
    // Block of faces f0 .. f1 - 1 of W pencils whose first cells are base, base + 1, ...
    const auto block = [&](auto pencils, std::ptrdiff_t base, int f0, int f1) {
      constexpr int W = decltype(pencils)::value;
      // Face f lies between cells f - 1 and f. The block first reconstructs both face states
      // of its cells f0 - 1 .. f1 - 1 (each cell's slopes once, field by field: simple loops
      // without a dependence from one cell to the next), then solves the faces' Riemann
      // problems.
      const int cells = f1 - f0 + 1;
      const std::ptrdiff_t c0 = base + (f0 - 1) * s;  // the block's cell q is c0 + q s
      FaceStates minus, plus;
      for (int v = 0; v < 7; ++v) {
        const double* x = fields[v];
        if (W == 2) {  // two pencils side by side: their cells are one Pair
          for (int q = 0; q < cells; ++q) reconstruct_pair<L>(x + c0 + q * s, s, minus[v] + 2 * q, plus[v] + 2 * q);
        } else if (s == 1) {  // a contiguous pencil: two cells per instruction
          reconstruct_run<L>(x + c0, cells, minus[v], plus[v]);
        } else {
          for (int q = 0; q < cells; ++q) {
            const std::ptrdiff_t c = c0 + q * s;
            reconstruct<L>(x[c - s], x[c], x[c + s], minus[v][q], plus[v][q]);
          }
        }
      }
      double change[variable_count][face_block * 2];  // flux / h of face f0 + b, pencil l: b W + l
      if (pressure) {
        int q = 0;
        if (W == 2)
          for (; q < cells; ++q) characteristic(c0 + q * s, s, un_index, 2 * q, minus, plus, Pair{});
        if (s == 1)
          for (; q + 2 <= cells; q += 2) characteristic(c0 + q, s, un_index, q, minus, plus, Pair{});
        for (; q < cells; ++q) characteristic(c0 + q * s, s, un_index, q, minus, plus, 0.0);
      }
      for (int f = f0; f < f1; ++f) {
        for (int lane = 0; lane < W; ++lane) {
          const int q = f - f0 + 1;  // the block index of cell f
          const std::ptrdiff_t cR = base + lane + f * s, cL = cR - s;
          double left[7], right[7];
          for (int v = 0; v < 7; ++v) {
            left[v] = plus[v][(q - 1) * W + lane];
            right[v] = minus[v][q * W + lane];
          }
          if (walls) {
            // Beside a wall the mirror ghost makes every even field a local extremum, and the
            // limiter would flatten the wall cell to first order (a hydrostatic layer would then
            // carry O(h) spurious velocities there). Even fields take a one-sided interior
            // slope instead (zero if a face value would leave [x/2, 2x]); u_z, odd, keeps the
            // mirror. The wall's own Riemann problem is the exact mirror image of the wall
            // cell's face state, so its mass and energy fluxes vanish by symmetry too.
            // The slope is the second-order one-sided difference (-3 x0 + 4 x1 - x2) / 2, exact
            // for quadratics like the interior central slope: the wall cell's face values then
            // carry the interior's O(h^2) error, and the jump at its interior face stays O(h^3).
            // The plain difference x1 - x0 is the slope at that face, not at the cell centre
            // (twice the centre slope of an even field): its O(h^2) jump, times the sound speed
            // in the Riemann flux's dissipation, was an O(h) truncation error in the wall cell
            // and a first-order density error there (MMS full_walls, n Linf pair orders 80 ->
            // 640 cells: 1.58 1.46 1.11 with x1 - x0; 1.97 2.00 to 320 cells with this slope).
            const int un = 1 + d;
            const auto wall_cell = [&](std::ptrdiff_t c, std::ptrdiff_t interior_step, double sign,
                                       double* face) {
              for (int v = 0; v < 7; ++v) {
                if (v == un) continue;
                const double x0 = fields[v][c];
                const double half_slope =
                    0.25 * (4.0 * fields[v][c + interior_step] - 3.0 * x0 -
                            fields[v][c + 2 * interior_step]);
                const double value = x0 + sign * half_slope, other = x0 - sign * half_slope;
                const bool keep = value >= 0.5 * x0 && value <= 2.0 * x0 && other >= 0.5 * x0 &&
                                  other <= 2.0 * x0;
                face[v] = keep ? value : x0;
              }
            };
            const auto mirror = [&](const double* from, double* to) {
              for (int v = 0; v < 7; ++v) to[v] = v == un ? -from[v] : from[v];
            };
            // sign: +1 when the wanted face lies on the interior side of the cell centre
            if (f == 0) {
              wall_cell(cR, s, -1.0, right);
              mirror(right, left);
            } else if (f == P.length) {
              wall_cell(cL, -s, -1.0, left);
              mirror(left, right);
            } else {
              if (f == 1) wall_cell(cL, s, +1.0, left);
              if (f == P.length - 1) wall_cell(cR, -s, +1.0, right);
            }
          }
          if (pressure) {
            std::swap(left[4], left[5]);  // left[5] = p, left[4] = chi
            std::swap(right[4], right[5]);
            left[4] = left[5] / (left[0] * left[4]);
            right[4] = right[5] / (right[0] * right[4]);
            // Near vacuum the independently limited n, p and chi can combine into a face
            // temperature far outside the neighbouring cells' range; such a side falls back to
            // its cell average (first order there). The band is a factor of 2 around the range,
            // so smooth flow (where p / (n chi) differs from T by O(h)) never triggers it.
            const double* T = w[4].data();
            const auto outside = [](double x, double a, double b, double c) {
              return !(x >= 0.5 * std::min({a, b, c}) && x <= 2.0 * std::max({a, b, c}));
            };
            if (outside(left[4], T[cL - s], T[cL], T[cR])) cell_state(cL, left);
            if (outside(right[4], T[cL], T[cR], T[cR + s])) cell_state(cR, right);
          } else {
            left[5] = right[5] = 0.0;
          }
          const int un = 1 + d, u1 = 1 + (d + 1) % 3, u2 = 1 + (d + 2) % 3;
          const FaceState SL{left[0], left[un], left[u1], left[u2], left[4], left[5], left[6]};
          const FaceState SR{right[0], right[un], right[u1], right[u2], right[4], right[5], right[6]};
          double F[5];
          riemann_flux<R>(SL, SR, F);
          if (walls && (f == 0 || f == P.length)) F[0] = F[2] = F[3] = F[4] = 0.0;
          const int b = (f - f0) * W + lane;
          change[density][b] = F[0] * inv_h;
          change[energy][b] = F[4] * inv_h;
          change[normal][b] = F[1] * inv_h;
          change[tangential1][b] = F[2] * inv_h;
          change[tangential2][b] = F[3] * inv_h;
        }
      }
      // Face f adds to cell f (its high side) and subtracts from cell f - 1. Each cell
      // receives its low face first, then its high face (in this block or the next), as in
      // a face-by-face loop; the two loops have no dependence from one face to the next.
      const int add_end = std::min(f1, P.length), subtract_begin = std::max(f0, 1);
      for (int v = 0; v < variable_count; ++v) {
        for (int lane = 0; lane < W; ++lane) {
          double* dU = dUdt.q[v].data() + base + lane;
          const double* ch = change[v] + lane;  // ch[(f - f0) W]: face f
          for (int f = f0; f < add_end; ++f) dU[f * s] += ch[(f - f0) * W];
          for (int f = subtract_begin; f < f1; ++f) dU[(f - 1) * s] -= ch[(f - f0) * W];
        }
      }
    };
    // Pencils across x (y and z faces) go two at a time: side by side in storage, one Pair
    // holds both (bit for bit the scalar arithmetic of each); an odd row's last pencil goes
    // alone (a decomposed box's blocks are often odd in x).
    // Dynamic scheduling: on a shared machine a thread that is held up does not hold up the
    // other (pencils touch disjoint cells, so the result does not depend on the order). A
    // chunk is a whole row or plane of pencils, so that two threads never write into the
    // same cache line.
    const bool paired = s != 1;
    const int per_row = paired ? (P.count_a + 1) / 2 : P.count_a;
    const int groups = per_row * P.count_b;
#pragma omp parallel for schedule(dynamic, per_row) if (g.threaded())
    for (int group = 0; group < groups; ++group) {
      const int a = paired ? 2 * (group % per_row) : group % per_row, b = group / per_row;
      const bool pair = paired && a + 1 < P.count_a;
      const std::ptrdiff_t base = P.base(g, d, a, b);
      for (int f0 = 0; f0 <= P.length; f0 += face_block) {
        const int f1 = std::min(f0 + face_block, P.length + 1);
        if (pair)
          block(std::integral_constant<int, 2>{}, base, f0, f1);
        else
          block(std::integral_constant<int, 1>{}, base, f0, f1);
      }
    }
  }
}

template <Limiter L>
void dispatch_riemann(RiemannSolver r, const Grid& g,
                      const std::array<std::vector<double>, variable_count>& w,
                      const Operator::Closure& closure, bool pressureful, State& dUdt) {
  if (r == RiemannSolver::hllc)
    inviscid_fluxes<L, RiemannSolver::hllc>(g, w, closure, pressureful, dUdt);
  else
    inviscid_fluxes<L, RiemannSolver::hll>(g, w, closure, pressureful, dUdt);
}
}  // namespace

void Operator::add_inviscid_fluxes(State& dUdt) {
  switch (settings_.limiter) {
    case Limiter::minmod:
      return dispatch_riemann<Limiter::minmod>(settings_.riemann, grid_, w_, closure_, settings_.terms.pressure, dUdt);
    case Limiter::mc:
      return dispatch_riemann<Limiter::mc>(settings_.riemann, grid_, w_, closure_, settings_.terms.pressure, dUdt);
    case Limiter::van_leer:
      return dispatch_riemann<Limiter::van_leer>(settings_.riemann, grid_, w_, closure_, settings_.terms.pressure, dUdt);
    case Limiter::none:
      return dispatch_riemann<Limiter::none>(settings_.riemann, grid_, w_, closure_, settings_.terms.pressure, dUdt);
  }
}

}  // namespace shaker::continuum
