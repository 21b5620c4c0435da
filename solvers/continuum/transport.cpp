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
  double p, c, mu, lambda, kappa;
};

CellClosure evaluate(const PhysicsSettings& s, double n, double T, double h, bool need_transport) {
  CellClosure r{0, 0, 0, 0, 0};
  const Terms& terms = s.terms;
  const double nu = volume_fraction(n);
  if (terms.pressure) {
    if (s.eos == EquationOfState::ideal_gas) {
      if (!(T >= 0.0)) model::detail::domain_failure("ideal gas", "T", T, "T >= 0");
      r.p = n * T;
      r.c = std::sqrt(5.0 / 3.0 * T);
    } else {
      r.p = model::pressure(n, T, s.e);
      r.c = model::sound_speed(nu, T, s.e);
    }
  }
  if (!need_transport) return r;
  if (terms.shear_viscosity) r.mu = model::shear_viscosity(n, T, s.transport);
  if (terms.bulk_viscosity) r.lambda = model::bulk_viscosity(n, T);
  if (terms.conduction) r.kappa = model::thermal_conductivity(n, T, s.transport);
  if (s.transport == model::Transport::paper && terms.artificial_dissipation) {
    const double x = nu / s.artificial.volume_fraction;
    const double x2 = x * x;
    const double weight = n * h * r.c / (1.0 + x2 * x2);
    if (terms.shear_viscosity) r.mu += s.artificial.viscosity * weight;
    if (terms.conduction) r.kappa += s.artificial.conductivity * weight;
  }
  return r;
}
}  // namespace

void Operator::update_primitives_and_closure(const State& U, bool need_transport) {
  const std::ptrdiff_t cells = static_cast<std::ptrdiff_t>(U.size());
  const double h = grid_.h;
  transport_evaluated_ = need_transport;
  // An exception must not leave an OpenMP region: the first failure is kept and rethrown.
  std::exception_ptr failure;
#pragma omp parallel for schedule(static) if (cells > 4096)
  for (std::ptrdiff_t c = 0; c < cells; ++c) {
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
    } catch (...) {
#pragma omp critical(shaker_closure_failure)
      if (!failure) failure = std::current_exception();
    }
  }
  if (failure) std::rethrow_exception(failure);
}

}  // namespace shaker::continuum
