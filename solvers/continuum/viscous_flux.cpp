// Viscous stress and heat flux through each face, centred and second order:
//   P = -p I + tau,  tau = (lambda - 2 mu / 3) (div u) I + 2 mu E,   q = -kappa grad T.
// Normal derivatives at a face are the difference of the two cells; tangential ones the mean
// of the two cells' central differences; coefficients the harmonic mean of the two cells: at the edge of the layer (a dense
// cell beside a near-vacuum one) an arithmetic mean would drive the dilute cell with the
// dense cell's diffusivity, far beyond the per-cell stability limit; the harmonic mean stays
// below twice the smaller coefficient and is second order all the same. In 1D the
// tangential derivatives are zero, which is exactly what the 3D kernel computes for a
// horizontally uniform state. At walls the heat, energy and tangential momentum fluxes are
// zero (no heat through the walls, zero normal gradient of the tangential velocity).
#include <algorithm>

#include "continuum/face_coefficients.hpp"
#include "continuum/operator.hpp"
#include "continuum/simd_pair.hpp"

namespace shaker::continuum {

namespace {

/// tau_zz at a wall, WallStress::second_order: cell 0 is the wall cell, cell 1 the next one
/// away from the wall, `toward` +1 at the bottom wall and -1 at the top (z runs away from the
/// bottom wall and towards the top one). u_z' at the wall is m' / n there, m = n u_z: the cells
/// hold averages of n and m, and (7 m_0 - m_1) / (2 h) is the slope at the wall of the
/// quadratic with m = 0 there whose cell averages they are, second order (the same formula in
/// u_z = m / n would be first order where n' u_z' != 0 at the wall: the average of a product is
/// not the product of the averages, by O(h^2), which the slope divides by h); the tangential
/// divergence (d u_x / dx + d u_y / dy, 0 in a column) extrapolated as the coefficients.
template <class S>
S wall_normal_stress(S n0, S n1, S mu0, S mu1, S lambda0, S lambda1, S u0, S u1, S tangential0,
                     S tangential1, double toward, double inv_h) {
  const S mu = extrapolated_to_wall(mu0, mu1), lambda = extrapolated_to_wall(lambda0, lambda1);
  const S normal = toward * (7.0 * (n0 * u0) - n1 * u1) * (0.5 * inv_h) / extrapolated_to_wall(n0, n1);
  const S tangential = 1.5 * tangential0 - 0.5 * tangential1;
  return (4.0 / 3.0 * mu + lambda) * normal + (lambda - 2.0 / 3.0 * mu) * tangential;
}
}  // namespace

namespace {
/// The 1D column's faces: the same arithmetic as the general kernel below for a grid without
/// x, y derivatives (the zero entries of its gradient kept in the sums, so the values agree
/// bit for bit), face fluxes first as simple loops over a block of faces, then added to the
/// cells.
void column_diffusive_fluxes(const Grid& g, const std::array<std::vector<double>, variable_count>& w,
                             const Operator::Closure& closure, WallStress wall_stress, State& dUdt) {
  constexpr int block = 64;
  const double inv_h = 1.0 / g.h;
  const double* u[3] = {w[1].data(), w[2].data(), w[3].data()};
  const double* T = w[4].data();
  const double* mu = closure.mu.data();
  const double* lambda = closure.lambda.data();
  const double* kappa = closure.kappa.data();
  const std::ptrdiff_t base = g.row_start(0);  // cell k of the column is base + k
  const int length = g.row_length();
  const bool walls = g.z_boundary == ZBoundary::walls;
  double* dU[3] = {dUdt.q[momentum_x].data(), dUdt.q[momentum_y].data(), dUdt.q[momentum_z].data()};
  double* dE = dUdt.q[energy].data();
  for (int f0 = 0; f0 <= length; f0 += block) {
    const int f1 = std::min(f0 + block, length + 1);
    double change[4][block];  // per unit time: momentum x, y, z, energy of face f0 + b
    // Face f0 + b (S = double) or faces f0 + b, f0 + b + 1, ... (S a vector, the same
    // arithmetic per lane).
    const auto faces = [&](int b, auto lanes) {
      using S = decltype(lanes);
      const auto at = [](const double* x) { return load_lanes<S>(x); };
      const std::ptrdiff_t cR = base + f0 + b, cL = cR - 1;
      const S mu_f = harmonic_mean(at(mu + cL), at(mu + cR));
      const S lambda_f = harmonic_mean(at(lambda + cL), at(lambda + cR));
      const S kappa_f = harmonic_mean(at(kappa + cL), at(kappa + cR));
      const S u_L[3] = {at(u[0] + cL), at(u[1] + cL), at(u[2] + cL)};
      const S u_R[3] = {at(u[0] + cR), at(u[1] + cR), at(u[2] + cR)};
      const S gx = (u_R[0] - u_L[0]) * inv_h;
      const S gy = (u_R[1] - u_L[1]) * inv_h;
      const S gz = (u_R[2] - u_L[2]) * inv_h;
      const S divergence = 0.0 + 0.0 + gz;
      const S tx = mu_f * (gx + 0.0), ty = mu_f * (gy + 0.0);
      S tz = mu_f * (gz + gz);
      tz += (lambda_f - 2.0 / 3.0 * mu_f) * divergence;
      S work = S{};
      work += tx * 0.5 * (u_L[0] + u_R[0]);
      work += ty * 0.5 * (u_L[1] + u_R[1]);
      work += tz * 0.5 * (u_L[2] + u_R[2]);
      store_lanes(&change[0][b], -tx * inv_h);
      store_lanes(&change[1][b], -ty * inv_h);
      store_lanes(&change[2][b], -tz * inv_h);
      store_lanes(&change[3][b], (-work - kappa_f * (at(T + cR) - at(T + cL)) * inv_h) * inv_h);
    };
    for_lanes(f1 - f0, faces);
    if (walls && wall_stress == WallStress::second_order) {
      // The same arithmetic as the 3D kernel's wall faces, whose tangential divergence is 0
      // in a horizontally uniform state.
      const auto wall_change = [&](std::ptrdiff_t c0, std::ptrdiff_t c1, double toward) {
        return -wall_normal_stress(w[0][c0], w[0][c1], mu[c0], mu[c1], lambda[c0], lambda[c1], u[2][c0],
                                   u[2][c1], 0.0, 0.0, toward, inv_h) * inv_h;
      };
      if (f0 == 0) change[2][0] = wall_change(base, base + 1, 1.0);
      if (f1 == length + 1) change[2][f1 - 1 - f0] = wall_change(base + length - 1, base + length - 2, -1.0);
    }
    if (walls && f0 == 0) change[0][0] = change[1][0] = change[3][0] = 0.0;
    if (walls && f1 == length + 1) change[0][f1 - 1 - f0] = change[1][f1 - 1 - f0] = change[3][f1 - 1 - f0] = 0.0;
    // Face f adds to cell f (its high side) and subtracts from cell f - 1. Each cell
    // receives its low face first, then its high face (in this block or the next), as in a
    // face-by-face loop; the two loops have no dependence from one face to the next.
    const int add_end = std::min(f1, length), subtract_begin = std::max(f0, 1);
    double* const targets[4] = {dU[0], dU[1], dU[2], dE};
    for (int v = 0; v < 4; ++v) {
      double* to = targets[v] + base;
      for (int f = f0; f < add_end; ++f) to[f] += change[v][f - f0];
      for (int f = subtract_begin; f < f1; ++f) to[f - 1] -= change[v][f - f0];
    }
  }
}
}  // namespace

namespace {
/// The viscous and heat fluxes through faces normal to direction d (a template parameter: the
/// gradient's index logic is resolved at compile time), added to dU/dt.
template <int d>
struct ViscousFaces {
  ViscousFaces(const Grid& g, const std::array<std::vector<double>, variable_count>& w,
               const Operator::Closure& closure, WallStress stress, State& change)
      : inv_h(1.0 / g.h), three_d(g.dimension == 3), u{w[1].data(), w[2].data(), w[3].data()}, n(w[0].data()),
        T(w[4].data()), mu(closure.mu.data()), lambda(closure.lambda.data()), kappa(closure.kappa.data()),
        strides{g.stride(0), g.stride(1), g.stride(2)}, s(strides[d]), wall_stress(stress), dUdt(change) {}

  double inv_h;
  bool three_d;
  const double* u[3];
  const double *n, *T, *mu, *lambda, *kappa;
  std::ptrdiff_t strides[3];
  std::ptrdiff_t s;
  WallStress wall_stress;
  State& dUdt;

  template <class S> static S at(const double* x) { return load_lanes<S>(x); }

  /// grad[i][j] = d u_i / d x_j at the face between cL and cR. Tangential derivatives enter
  /// only through d u_d / d x_t and the divergence (d u_t / d x_t); the other two are not
  /// needed.
  template <class S> void velocity_gradient(std::ptrdiff_t cL, std::ptrdiff_t cR, S (&grad)[3][3]) const {
    for (int i = 0; i < 3; ++i) {
      grad[i][d] = (at<S>(u[i] + cR) - at<S>(u[i] + cL)) * inv_h;
      if (!three_d) continue;
      for (int t = 0; t < 3; ++t) {
        if (t == d || (i != d && i != t)) continue;
        const std::ptrdiff_t st = strides[t];
        grad[i][t] = 0.25 * inv_h * (at<S>(u[i] + cL + st) - at<S>(u[i] + cL - st) + at<S>(u[i] + cR + st) -
                                     at<S>(u[i] + cR - st));
      }
    }
  }

  /// d u_x / dx + d u_y / dy at cell c (0 in a column).
  template <class S> S tangential_divergence(std::ptrdiff_t c) const {
    if (!three_d) return S{};
    return 0.5 * inv_h * (at<S>(u[0] + c + strides[0]) - at<S>(u[0] + c - strides[0])) +
           0.5 * inv_h * (at<S>(u[1] + c + strides[1]) - at<S>(u[1] + c - strides[1]));
  }

  /// A wall face: no heat, energy or tangential momentum flux; the normal stress as the
  /// settings say (`bottom`: the bottom wall, whose wall cell is cR; else the top wall's, cL).
  template <class S> void wall_flux(std::ptrdiff_t cL, std::ptrdiff_t cR, bool bottom, S (&flux)[variable_count]) const {
    flux[energy] = S{};
    for (int i = 0; i < 3; ++i)
      if (i != d) flux[momentum_x + i] = S{};
    if (wall_stress != WallStress::second_order) return;
    const std::ptrdiff_t c0 = bottom ? cR : cL, c1 = bottom ? cR + s : cL - s;
    flux[momentum_z] = -wall_normal_stress(at<S>(n + c0), at<S>(n + c1), at<S>(mu + c0), at<S>(mu + c1),
                                           at<S>(lambda + c0), at<S>(lambda + c1), at<S>(u[2] + c0),
                                           at<S>(u[2] + c1), tangential_divergence<S>(c0),
                                           tangential_divergence<S>(c1), bottom ? 1.0 : -1.0, inv_h);
  }

  /// The face whose high-side cell is cR (S = double), or the faces of cells cR, cR + 1, ...
  /// (S a vector: x-neighbours, either pencils side by side or faces of an x pencil), every
  /// lane doing the scalar arithmetic. `add` / `subtract`: the face adds to its high
  /// cell / subtracts from its low cell (not both at the ends of a pencil).
  template <class S> void operator()(std::ptrdiff_t cR, bool add, bool subtract, bool wall, S) const {
    const std::ptrdiff_t cL = cR - s;
    S grad[3][3] = {};
    velocity_gradient(cL, cR, grad);
    const S mu_f = harmonic_mean(at<S>(mu + cL), at<S>(mu + cR));
    const S lambda_f = harmonic_mean(at<S>(lambda + cL), at<S>(lambda + cR));
    const S kappa_f = harmonic_mean(at<S>(kappa + cL), at<S>(kappa + cR));
    const S divergence = grad[0][0] + grad[1][1] + grad[2][2];
    S flux[variable_count] = {};
    S work = S{};
    for (int i = 0; i < 3; ++i) {
      S tau = mu_f * (grad[i][d] + grad[d][i]);
      if (i == d) tau += (lambda_f - 2.0 / 3.0 * mu_f) * divergence;
      flux[momentum_x + i] = -tau;
      work += tau * 0.5 * (at<S>(u[i] + cL) + at<S>(u[i] + cR));
    }
    flux[energy] = -work - kappa_f * (at<S>(T + cR) - at<S>(T + cL)) * inv_h;
    if (wall) wall_flux(cL, cR, add, flux);
    for (int v = momentum_x; v < variable_count; ++v) {
      const S change = flux[v] * inv_h;
      double* dU = dUdt.q[v].data();
      if (add) store_lanes(dU + cR, at<S>(dU + cR) + change);
      if (subtract) store_lanes(dU + cL, at<S>(dU + cL) - change);
    }
  }
};

/// Faces normal to d of the planes k0 .. k1 - 1 (slab_sweep).
template <int d>
void diffusive_fluxes_along(const Grid& g, const std::array<std::vector<double>, variable_count>& w,
                            const Operator::Closure& closure, WallStress wall_stress, State& dUdt,
                            int k0, int k1) {
  const ViscousFaces<d> face(g, w, closure, wall_stress, dUdt);
  const std::ptrdiff_t s = face.s;
  const int n_a = d == 0 ? g.ny : g.nx;
  const int length = d == 0 ? g.nx : d == 1 ? g.ny : g.nz;
  const bool walls = d == 2 && g.z_boundary == ZBoundary::walls;
  // y and z faces: a vector's width of pencils side by side (a row's last ones narrower); x
  // faces: a vector's width of faces at a time between the pencil's end faces. Either way each
  // cell receives its low face before its high face, as in the face-by-face loop, so the sums
  // are the same bit for bit.
  constexpr int width = lanes_of<Wide>;
  const bool across = d != 0;
  const int per_row = across ? (n_a + width - 1) / width : n_a;
  const SlabSweep part = slab_sweep(g, d, k0, k1);
  const int groups = per_row * part.b_count;
#pragma omp parallel for schedule(dynamic, per_row) if (g.threaded())
  for (int group = 0; group < groups; ++group) {
    const int a = across ? width * (group % per_row) : group % per_row, b = part.b_first + group / per_row;
    const std::ptrdiff_t base = d == 0 ? g.index(0, a, b) : d == 1 ? g.index(a, 0, b) : g.index(a, b, 0);
    if (across) {
      const int pencils = std::min(width, n_a - a);
      const auto wall_face = [&](int f) { return walls && (f == 0 || f == length); };
      for (int f = part.f_begin; f < part.f_end; ++f)
        for_lanes(pencils, [&](int l, auto lanes) { face(base + f * s + l, f < length, f > 0, wall_face(f), lanes); });
      continue;
    }
    face(base, true, false, false, 0.0);
    for_lanes(length - 1, [&](int i, auto lanes) { face(base + 1 + i, true, true, false, lanes); });
    face(base + length, false, true, false, 0.0);
  }
}
}  // namespace

void Operator::add_diffusive_fluxes(State& dUdt, int k0, int k1) {
  const Grid& g = grid_;
  const WallStress wall_stress = settings_.wall_stress;
  if (g.dimension != 3 && g.nx == 1 && g.ny == 1)  // rhs passes a column whole
    return column_diffusive_fluxes(g, w_, closure_, wall_stress, dUdt);
  if (g.first_direction() == 0) {
    diffusive_fluxes_along<0>(g, w_, closure_, wall_stress, dUdt, k0, k1);
    diffusive_fluxes_along<1>(g, w_, closure_, wall_stress, dUdt, k0, k1);
  }
  diffusive_fluxes_along<2>(g, w_, closure_, wall_stress, dUdt, k0, k1);
}

}  // namespace shaker::continuum
