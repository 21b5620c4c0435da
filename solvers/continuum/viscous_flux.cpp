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
#include "continuum/operator.hpp"

namespace shaker::continuum {

namespace {
inline double harmonic_mean(double a, double b) {
  const double sum = a + b;
  return sum > 0.0 ? 2.0 * a * b / sum : 0.0;
}
}  // namespace

void Operator::add_diffusive_fluxes(State& dUdt) {
  const Grid& g = grid_;
  const double inv_h = 1.0 / g.h;
  const bool three_d = g.dimension == 3;
  const double* u[3] = {w_[1].data(), w_[2].data(), w_[3].data()};
  const double* T = w_[4].data();
  const double* mu = closure_.mu.data();
  const double* lambda = closure_.lambda.data();
  const double* kappa = closure_.kappa.data();
  for (int d = g.first_direction(); d < 3; ++d) {
    const std::ptrdiff_t s = g.stride(d);
    const int n_a = d == 0 ? g.ny : g.nx, n_b = d == 2 ? g.ny : g.nz;
    const int length = d == 0 ? g.nx : d == 1 ? g.ny : g.nz;
    const bool walls = d == 2 && g.z_boundary == ZBoundary::walls;
    const int total = n_a * n_b;
#pragma omp parallel for schedule(dynamic, n_a) if (total > 1 && g.interior_cells() > 4096)
    for (int pencil = 0; pencil < total; ++pencil) {
      const int a = pencil % n_a, b = pencil / n_a;
      const std::ptrdiff_t base = d == 0 ? g.index(0, a, b) : d == 1 ? g.index(a, 0, b) : g.index(a, b, 0);
      for (int f = 0; f <= length; ++f) {
        const std::ptrdiff_t cR = base + f * s, cL = cR - s;
        // grad[i][j] = d u_i / d x_j at the face
        double grad[3][3] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
        // Tangential derivatives enter only through d u_d / d x_t and the divergence
        // (d u_t / d x_t); the other two are not needed.
        for (int i = 0; i < 3; ++i) {
          grad[i][d] = (u[i][cR] - u[i][cL]) * inv_h;
          if (!three_d) continue;
          for (int t = 0; t < 3; ++t) {
            if (t == d || (i != d && i != t)) continue;
            const std::ptrdiff_t st = g.stride(t);
            grad[i][t] = 0.25 * inv_h * (u[i][cL + st] - u[i][cL - st] + u[i][cR + st] - u[i][cR - st]);
          }
        }
        const double mu_f = harmonic_mean(mu[cL], mu[cR]);
        const double lambda_f = harmonic_mean(lambda[cL], lambda[cR]);
        const double kappa_f = harmonic_mean(kappa[cL], kappa[cR]);
        const double divergence = grad[0][0] + grad[1][1] + grad[2][2];
        double flux[variable_count] = {0, 0, 0, 0, 0};
        double work = 0.0;
        for (int i = 0; i < 3; ++i) {
          double tau = mu_f * (grad[i][d] + grad[d][i]);
          if (i == d) tau += (lambda_f - 2.0 / 3.0 * mu_f) * divergence;
          flux[momentum_x + i] = -tau;
          work += tau * 0.5 * (u[i][cL] + u[i][cR]);
        }
        flux[energy] = -work - kappa_f * (T[cR] - T[cL]) * inv_h;
        if (walls && (f == 0 || f == length)) {
          flux[energy] = 0.0;
          for (int i = 0; i < 3; ++i)
            if (i != d) flux[momentum_x + i] = 0.0;
        }
        for (int v = momentum_x; v < variable_count; ++v) {
          const double change = flux[v] * inv_h;
          if (f < length) dUdt.q[v][cR] += change;
          if (f > 0) dUdt.q[v][cL] -= change;
        }
      }
    }
  }
}

}  // namespace shaker::continuum
