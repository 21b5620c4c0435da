// Primitive variables and the closure (pressure, sound speed, transport coefficients) per
// cell, from the constitutive functions of common/granular_model.hpp only.
//
// Transport variants (physics.md): `full` keeps every term of mu and kappa; `paper` drops
// their 1/G terms (the model functions do that) and adds the artificial dissipation of
// ArtificialDissipation (operator.hpp), which acts only where nu is well below
// artificial.volume_fraction.
#include <cmath>
#include <exception>

#include "continuum/operator.hpp"

namespace shaker::continuum {

namespace {
struct CellClosure {
  double p, c, mu, lambda, kappa, loss;
};

// One fused evaluation of the model per cell (model::constitutive_values: G once), and only
// when some enabled term needs it.
CellClosure evaluate(const PhysicsSettings& s, double n, double T, double h, bool need_transport) {
  CellClosure r{0, 0, 0, 0, 0, 0};
  const Terms& terms = s.terms;
  const bool ideal = s.eos == EquationOfState::ideal_gas;
  if (ideal && terms.pressure) {
    if (!(T >= 0.0)) model::detail::domain_failure("ideal gas", "T", T, "T >= 0");
    r.p = n * T;
    r.c = std::sqrt(5.0 / 3.0 * T);
  }
  const bool transport = need_transport && (terms.shear_viscosity || terms.bulk_viscosity || terms.conduction);
  if (!((terms.pressure && !ideal) || terms.collisional_loss || transport)) return r;
  const model::ConstitutiveValues<double> m = model::constitutive_values(n, T, s.e, s.transport);
  if (terms.pressure && !ideal) {
    r.p = m.pressure;
    r.c = m.sound_speed;
  }
  if (terms.collisional_loss) r.loss = m.collisional_loss;
  if (!need_transport) return r;
  if (terms.shear_viscosity) r.mu = m.shear_viscosity;
  if (terms.bulk_viscosity) r.lambda = m.bulk_viscosity;
  if (terms.conduction) r.kappa = m.thermal_conductivity;
  if (s.transport == model::Transport::paper && terms.artificial_dissipation) {
    const double x = volume_fraction(n) / s.artificial.volume_fraction;
    const double x2 = x * x;
    const double weight = n * h * r.c / (1.0 + x2 * x2);
    if (terms.shear_viscosity) r.mu += s.artificial.viscosity * weight;
    if (terms.conduction) r.kappa += s.artificial.conductivity * weight;
  }
  return r;
}
}  // namespace

void Operator::update_primitives_and_closure(const State& U, bool need_transport) {
  const Grid& g = grid_;
  const double h = g.h;
  transport_evaluated_ = need_transport;
  // Interior cells only (ghosts copy theirs afterwards), row by row along x. Dynamic
  // scheduling: on a shared machine a thread that is held up does not hold up the other.
  const int rows = g.ny * g.nz;
  // An exception must not leave an OpenMP region: the first failure is kept and rethrown.
  std::exception_ptr failure;
#pragma omp parallel for schedule(dynamic, 16) if (g.interior_cells() > 4096)
  for (int row = 0; row < rows; ++row) {
    const std::ptrdiff_t first = g.index(0, row % g.ny, row / g.ny);
    for (std::ptrdiff_t c = first; c < first + g.nx; ++c) {
      try {
        const Primitive w = to_primitive(U, static_cast<std::size_t>(c));
        w_[0][c] = w.n;
        w_[1][c] = w.ux;
        w_[2][c] = w.uy;
        w_[3][c] = w.uz;
        w_[4][c] = w.T;
        const CellClosure r = evaluate(settings_, w.n, w.T, h, need_transport);
        closure_.p[c] = r.p;
        closure_.c[c] = r.c;
        closure_.chi[c] = w.T > 0.0 ? r.p / (w.n * w.T) : 1.0;
        closure_.mu[c] = r.mu;
        closure_.lambda[c] = r.lambda;
        closure_.kappa[c] = r.kappa;
        closure_.loss[c] = r.loss;
      } catch (...) {
#pragma omp critical(shaker_closure_failure)
        if (!failure) failure = std::current_exception();
      }
    }
  }
  if (failure) std::rethrow_exception(failure);
  copy_closure_to_ghosts();
}

}  // namespace shaker::continuum
