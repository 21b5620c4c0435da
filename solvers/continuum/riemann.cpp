// Inviscid fluxes: limited MUSCL reconstruction of (n, u, T, p, c) to both sides of each face
// (each cell's slopes computed once, for both of its faces) and an approximate Riemann solver. Reconstructed are n, u, p, chi = p / (n T) and c; the
// face temperature is p / (n chi), so pressure and internal energy stay consistent across a
// contact (no pressure wiggles), and the equation of state is not re-evaluated at faces
// (second order all the same, two fewer closure evaluations per face). Pressureless runs
// reconstruct T itself. At wall faces only the normal momentum flux
// (the wall pressure) survives; mass, energy and tangential momentum fluxes are exactly zero,
// so mass is conserved to round-off.
#include <algorithm>

#include "continuum/reconstruct.hpp"
#include "continuum/riemann.hpp"

namespace shaker::continuum {

namespace {

/// The cells of one direction as pencils (a, b), `length` cells each, count_a across a row
/// (the b of a slab: slab_sweep); base index of each pencil.
struct Pencils {
  int count_a, length;
  std::ptrdiff_t base(const Grid& g, int d, int a, int b) const {
    return d == 0 ? g.index(0, a, b) : d == 1 ? g.index(a, 0, b) : g.index(a, b, 0);
  }
};
Pencils pencils_of(const Grid& g, int d) {
  if (d == 0) return {g.ny, g.nx};
  if (d == 1) return {g.nx, g.ny};
  return {g.nx, g.nz};
}

/// Slots (cells x pencils) of a block: its face states (2 x 7 x slots doubles) stay in L1/L2.
constexpr int block_slots = 384;
/// Most pencils side by side in one block (a longer row is cut into balanced runs).
constexpr int max_lanes = 32;

template <Limiter L, RiemannSolver R>
void inviscid_fluxes(const Grid& g, const std::array<std::vector<double>, variable_count>& w,
                     const Operator::Closure& closure, bool pressureful, State& dUdt, int k0, int k1) {
  const double inv_h = 1.0 / g.h;
  const bool pressure = pressureful;
  const double* fields[7] = {w[0].data(),  w[1].data(),
                             w[2].data(),  w[3].data(),
                             pressure ? closure.p.data() : w[4].data(),
                             closure.chi.data(), closure.c.data()};
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
  // of pencil `lane`, slot = q W + lane, for W pencils side by side in x at once (their cells
  // are adjacent in storage).
  using FaceStates = double[7][block_slots];
  // S = double: cell c; S a vector: cells c, c + 1, ..., either of a contiguous pencil (s = 1,
  // slots q, q + 1, ...) or of pencils side by side (lanes l, l + 1, ... of cell q), every
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
    // (no sound speed, or a face value that is not positive: the component-wise values, what
    // reconstruct_lanes gives from the same differences)
    const auto keep = (c0 > 0.0) & (n_plus > 0.0) & (p_plus > 0.0) & (n_minus > 0.0) & (p_minus > 0.0);
    const S half_n = 0.5 * limited_slope<L>(dn_b, dn_f), half_u = 0.5 * limited_slope<L>(du_b, du_f),
            half_p = 0.5 * limited_slope<L>(dp_b, dp_f);
    store_lanes(&plus[0][q], keep ? n_plus : n0 + half_n);
    store_lanes(&plus[un][q], keep ? u0 + 0.5 * du : u0 + half_u);
    store_lanes(&plus[4][q], keep ? p_plus : p0 + half_p);
    store_lanes(&minus[0][q], keep ? n_minus : n0 - half_n);
    store_lanes(&minus[un][q], keep ? u0 - 0.5 * du : u0 - half_u);
    store_lanes(&minus[4][q], keep ? p_minus : p0 - half_p);
  };
  // The faces of direction d that belong to planes k0 .. k1 - 1 (slab_sweep).
  const auto sweep = [&](int d) {
    const std::ptrdiff_t s = g.stride(d);
    const int un_index = 1 + d;
    const Pencils P = pencils_of(g, d);
    const bool walls = d == 2 && g.z_boundary == ZBoundary::walls;
    const int normal = momentum_x + d;
    const int tangential1 = momentum_x + (d + 1) % 3, tangential2 = momentum_x + (d + 2) % 3;
    // Beside a wall the mirror ghost makes every even field a local extremum, and the limiter
    // would flatten the wall cell to first order (a hydrostatic layer would then carry O(h)
    // spurious velocities there). Even fields take a one-sided interior slope instead (zero if
    // a face value would leave [x/2, 2x]); u_z, odd, keeps the mirror. The wall's own Riemann
    // problem is the exact mirror image of the wall cell's face state, so its mass and energy
    // fluxes vanish by symmetry too.
    // The slope is the second-order one-sided difference (-3 x0 + 4 x1 - x2) / 2, exact for
    // quadratics like the interior central slope: the wall cell's face values then carry the
    // interior's O(h^2) error, and the jump at its interior face stays O(h^3). The plain
    // difference x1 - x0 is the slope at that face, not at the cell centre (twice the centre
    // slope of an even field): its O(h^2) jump, times the sound speed in the Riemann flux's
    // dissipation, was an O(h) truncation error in the wall cell and a first-order density
    // error there (MMS full_walls, n Linf pair orders 80 -> 640 cells: 1.58 1.46 1.11 with
    // x1 - x0; 1.97 2.00 to 320 cells with this slope).
    // sign: +1 when the wanted face lies on the interior side of the cell centre.
    const auto wall_cell = [&](std::ptrdiff_t c, std::ptrdiff_t interior_step, double sign, auto& face, int slot) {
      for (int v = 0; v < 7; ++v) {
        if (v == un_index) continue;
        const double x0 = fields[v][c];
        const double half_slope =
            0.25 * (4.0 * fields[v][c + interior_step] - 3.0 * x0 - fields[v][c + 2 * interior_step]);
        const double value = x0 + sign * half_slope, other = x0 - sign * half_slope;
        const bool keep = value >= 0.5 * x0 && value <= 2.0 * x0 && other >= 0.5 * x0 && other <= 2.0 * x0;
        face[v][slot] = keep ? value : x0;
      }
    };
    const auto mirror = [&](const auto& from, int from_slot, auto& to, int to_slot) {
      for (int v = 0; v < 7; ++v) to[v][to_slot] = v == un_index ? -from[v][from_slot] : from[v][from_slot];
    };
    // The face states of wall face f (0 or P.length) and of the wall cells' interior faces
    // (1, P.length - 1) of the pencil whose first cell is `first`; the face's left state is
    // plus[.][left], its right one minus[.][left + W].
    const auto wall_face = [&](std::ptrdiff_t first, int f, int left, int W, auto& minus, auto& plus) {
      const int right = left + W;
      const std::ptrdiff_t cR = first + f * s, cL = cR - s;
      if (f == 0) {
        wall_cell(cR, s, -1.0, minus, right);
        mirror(minus, right, plus, left);
      } else if (f == P.length) {
        wall_cell(cL, -s, -1.0, plus, left);
        mirror(plus, left, minus, right);
      } else {
        if (f == 1) wall_cell(cL, s, +1.0, plus, left);
        if (f == P.length - 1) wall_cell(cR, -s, +1.0, minus, right);
      }
    };
    // Pressureful face states hold p in x[4] and chi in x[5]; this makes them (T, p), with
    // T = p / (n chi). Near vacuum the independently limited n, p and chi can combine into a
    // face temperature far outside the neighbouring cells' range; such a face state falls back
    // to its cell's average (first order there). The band is a factor of 2 around the range,
    // so smooth flow (where p / (n chi) differs from T by O(h)) never triggers it.
    // Both face states of the cells at c (slot `slot`), which share the cells' range.
    const auto face_temperatures = [&](std::ptrdiff_t c, int slot, FaceStates& low_faces,
                                       FaceStates& high_faces, auto lanes) {
      using S = decltype(lanes);
      using pair_detail::larger;
      using pair_detail::smaller;
      const double* T = w[4].data();
      const auto at = [](const double* y) { return load_lanes<S>(y); };
      const S Tb = at(T + c - s), Tc = at(T + c), Tf = at(T + c + s);
      const S low = 0.5 * smaller(smaller(Tb, Tc), Tf), high = 2.0 * larger(larger(Tb, Tc), Tf);
      for (FaceStates* x : {&low_faces, &high_faces}) {
        const S p = at(&(*x)[4][slot]), T_face = p / (at(&(*x)[0][slot]) * at(&(*x)[5][slot]));
        const auto inside = (T_face >= low) & (T_face <= high);
        store_lanes(&(*x)[4][slot], inside ? T_face : Tc);
        store_lanes(&(*x)[5][slot], inside ? p : at(closure.p.data() + c));
        if (any_lane(!inside))  // rare: the other fields fall back to the cell's too
          for (int v : {0, 1, 2, 3, 6}) store_lanes_where(!inside, &(*x)[v][slot], at(fields[v] + c));
      }
    };
    // Block of faces f0 .. f1 - 1 of W pencils whose first cells are base, base + 1, ...
    // (W = 1 along x: a pencil is a row, contiguous).
    const auto block = [&](int W, std::ptrdiff_t base, int f0, int f1) {
      // Face f lies between cells f - 1 and f. The block first reconstructs both face states
      // of its cells f0 - 1 .. f1 - 1 (each cell's slopes once, field by field: simple loops
      // without a dependence from one cell to the next), then solves the faces' Riemann
      // problems.
      const int cells = f1 - f0 + 1;
      const std::ptrdiff_t c0 = base + (f0 - 1) * s;  // the block's cell q of pencil l is c0 + q s + l
      // Calls step(c, slot, lanes) for every cell of the block, `lanes` a double or a vector of
      // adjacent cells (simd_pair.hpp, for_lanes): a cell's pencils (W > 1) or the run (W = 1).
      const auto over_cells = [&](auto step) {
        if (W == 1 && s == 1) return for_lanes(cells, [&](int q, auto lanes) { step(c0 + q, q, lanes); });
        for (int q = 0; q < cells; ++q)
          for_lanes(W, [&](int lane, auto lanes) { step(c0 + q * s + lane, q * W + lane, lanes); });
      };
      FaceStates minus, plus;
      for (int v = 0; v < 7; ++v) {
        if (pressure && (v == 0 || v == un_index || v == 4)) continue;  // characteristic() does these
        const double* x = fields[v];
        over_cells([&](std::ptrdiff_t c, int slot, auto lanes) {
          reconstruct_lanes<L, decltype(lanes)>(x + c, s, minus[v] + slot, plus[v] + slot);
        });
      }
      if (pressure)
        over_cells([&](std::ptrdiff_t c, int slot, auto lanes) {
          characteristic(c, s, un_index, slot, minus, plus, lanes);
        });
      // Face f0 + b of pencil `lane` has its left state in plus[.][b W + lane] and its right
      // one in minus[.][(b + 1) W + lane]: consecutive slots are consecutive faces (W = 1) or
      // the same face of neighbouring pencils, a vector of them at a time either way.
      if (walls)
        for (int f = f0; f < f1; ++f)
          if (f <= 1 || f >= P.length - 1)
            for (int lane = 0; lane < W; ++lane) wall_face(base + lane, f, (f - f0) * W + lane, W, minus, plus);
      if (pressure)
        over_cells([&](std::ptrdiff_t c, int slot, auto lanes) {
          face_temperatures(c, slot, minus, plus, lanes);
        });
      const int slots = (f1 - f0) * W;
      double change[variable_count][block_slots];  // flux / h of face f0 + b, pencil l: b W + l
      const auto solve = [&](int b, auto lanes) {
        using S = decltype(lanes);
        const auto side = [&](const FaceStates& x, int slot) {
          const auto at = [&](int v) { return load_lanes<S>(&x[v][slot]); };
          return FaceStateOf<S>{at(0), at(un_index), at(1 + (d + 1) % 3), at(1 + (d + 2) % 3), at(4),
                                pressure ? at(5) : S{}, at(6)};
        };
        S F[5];
        riemann_flux<R>(side(plus, b), side(minus, b + W), F);
        store_lanes(&change[density][b], F[0] * inv_h);
        store_lanes(&change[energy][b], F[4] * inv_h);
        store_lanes(&change[normal][b], F[1] * inv_h);
        store_lanes(&change[tangential1][b], F[2] * inv_h);
        store_lanes(&change[tangential2][b], F[3] * inv_h);
      };
      for_lanes(slots, solve);
      // The wall's mass, energy and tangential momentum fluxes are zero exactly.
      if (walls)
        for (int f : {0, P.length})
          if (f >= f0 && f < f1)
            for (int lane = 0; lane < W; ++lane)
              for (int v : {int{density}, int{energy}, tangential1, tangential2}) change[v][(f - f0) * W + lane] = 0.0;
      // Face f adds to cell f (its high side) and subtracts from cell f - 1. Each cell
      // receives its low face first, then its high face (in this block or the next), as in
      // a face-by-face loop; the loops run along the pencils' row, contiguous in storage.
      const int add_end = std::min(f1, P.length), subtract_begin = std::max(f0, 1);
      for (int v = 0; v < variable_count; ++v) {
        double* dU = dUdt.q[v].data() + base;
        const double* ch = change[v];  // ch[(f - f0) W + lane]: face f of pencil lane
        if (W == 1) {
          for (int f = f0; f < add_end; ++f) dU[f * s] += ch[f - f0];
          for (int f = subtract_begin; f < f1; ++f) dU[(f - 1) * s] -= ch[f - f0];
          continue;
        }
        for (int f = f0; f < add_end; ++f)
          for (int lane = 0; lane < W; ++lane) dU[f * s + lane] += ch[(f - f0) * W + lane];
        for (int f = subtract_begin; f < f1; ++f)
          for (int lane = 0; lane < W; ++lane) dU[(f - 1) * s + lane] -= ch[(f - f0) * W + lane];
      }
    };
    // Pencils across x (y and z faces) go a run of a row at a time (at most max_lanes, a longer
    // row cut into balanced runs): side by side in storage, their cells are reconstructed and
    // their fluxes added as contiguous rows, and neighbours share a vector (bit for bit the
    // scalar arithmetic of each). Blocks along the pencils hold block_slots slots.
    // Dynamic scheduling: on a shared machine a thread that is held up does not hold up the
    // other (pencils touch disjoint cells, so the result does not depend on the order). A
    // chunk is a whole row or plane of pencils, so that two threads rarely write into the
    // same cache line.
    const bool across = s != 1;
    const int runs_per_row = across ? (P.count_a + max_lanes - 1) / max_lanes : P.count_a;
    const SlabSweep part = slab_sweep(g, d, k0, k1);
    const int groups = runs_per_row * part.b_count;
#pragma omp parallel for schedule(dynamic, runs_per_row) if (g.threaded())
    for (int group = 0; group < groups; ++group) {
      const int run = group % runs_per_row, b = part.b_first + group / runs_per_row;
      const int a = across ? run * P.count_a / runs_per_row : run;
      const int W = across ? (run + 1) * P.count_a / runs_per_row - a : 1;
      const std::ptrdiff_t base = P.base(g, d, a, b);
      const int faces_per_block = block_slots / W - 1;
      for (int f0 = part.f_begin; f0 < part.f_end; f0 += faces_per_block)
        block(W, base, f0, std::min(f0 + faces_per_block, part.f_end));
    }
  };
  for (int d = g.first_direction(); d < 3; ++d) sweep(d);
}

template <Limiter L>
void dispatch_riemann(RiemannSolver r, const Grid& g,
                      const std::array<std::vector<double>, variable_count>& w,
                      const Operator::Closure& closure, bool pressureful, State& dUdt, int k0, int k1) {
  if (r == RiemannSolver::hllc)
    inviscid_fluxes<L, RiemannSolver::hllc>(g, w, closure, pressureful, dUdt, k0, k1);
  else
    inviscid_fluxes<L, RiemannSolver::hll>(g, w, closure, pressureful, dUdt, k0, k1);
}
}  // namespace

void Operator::add_inviscid_fluxes(State& dUdt, int k0, int k1) {
  switch (settings_.limiter) {
    case Limiter::minmod:
      return dispatch_riemann<Limiter::minmod>(settings_.riemann, grid_, w_, closure_, settings_.terms.pressure, dUdt, k0, k1);
    case Limiter::mc:
      return dispatch_riemann<Limiter::mc>(settings_.riemann, grid_, w_, closure_, settings_.terms.pressure, dUdt, k0, k1);
    case Limiter::van_leer:
      return dispatch_riemann<Limiter::van_leer>(settings_.riemann, grid_, w_, closure_, settings_.terms.pressure, dUdt, k0, k1);
    case Limiter::none:
      return dispatch_riemann<Limiter::none>(settings_.riemann, grid_, w_, closure_, settings_.terms.pressure, dUdt, k0, k1);
  }
}

}  // namespace shaker::continuum
