// The closure (pressure, sound speed, transport coefficients, collisional loss) per cell, from
// the constitutive functions of common/granular_model.hpp only, and the row loop that forms
// the primitives (primitives.cpp) and the closure a row at a time.
//
// Transport variants (docs/models.md): `full` keeps every term of mu and kappa; `paper` drops
// their 1/G terms (the model functions do that) and adds the artificial dissipation of
// ArtificialDissipation (operator.hpp), which acts only where nu is well below
// artificial.volume_fraction.
//
// Speed: the closure is a chain of divisions, square roots and a pow per cell, whose latency
// dominated a cell update when evaluated cell by cell. The model's functions are templates
// over the scalar type, so the same definitions are evaluated here on Lanes, a few cells at
// once: every lane does exactly the arithmetic of the double version (the same operations in
// the same order, pow and sqrt per lane), so the values are bit for bit those of a cell-by-cell
// evaluation, while the lanes' independent chains overlap and the arithmetic vectorises.
// A group of cells any of which is outside the model's domain is evaluated cell by cell
// instead, which throws the model's own DomainError for the first such cell.
#include <algorithm>
#include <cmath>
#include <exception>
#include <type_traits>

#include "continuum/operator.hpp"
#include "continuum/simd_pair.hpp"

namespace shaker::continuum {

namespace {

/// W cells' values of one scalar, a vector (simd_pair.hpp): the arithmetic the model
/// templates use, one instruction for all lanes, each lane the double's arithmetic.
template <int W> struct Lanes {
  using Vector = typename DoubleLanes<W>::type;
  Vector v;
  Lanes() = default;
  Lanes(double x) : v(Vector{} + x) {}  // NOLINT: implicit, like the double operands of the model's formulas
  explicit Lanes(Vector x) : v(x) {}
  /// The model's domain checks look at value_of(x); every lane is checked before evaluation.
  double value() const { return v[0]; }
  friend Lanes operator+(const Lanes& a, const Lanes& b) { return Lanes(a.v + b.v); }
  friend Lanes operator-(const Lanes& a, const Lanes& b) { return Lanes(a.v - b.v); }
  friend Lanes operator*(const Lanes& a, const Lanes& b) { return Lanes(a.v * b.v); }
  friend Lanes operator/(const Lanes& a, const Lanes& b) { return Lanes(a.v / b.v); }
  Lanes& operator+=(const Lanes& b) { return *this = *this + b; }
  friend Lanes sqrt(const Lanes& a) {
    Lanes r;
    for (int l = 0; l < W; ++l) r.v[l] = std::sqrt(a.v[l]);
    return r;
  }
};

/// pow remembered per cell. The model's only pow is (nu / nu_max)^(4 nu_max / 3), a function
/// of the density alone, and the split integrators evaluate the closure twice at the same
/// density (the diffusive half steps change u and T only): a lane whose argument equals the
/// one remembered for its cell takes the remembered value (the same bits), the others call
/// std::pow and remember. The memo of the lane group being evaluated.
struct PowMemo {
  double argument[4], value[4];
};
constexpr int lane_count = 4;
using Cells = Lanes<lane_count>;

/// The model's g0 power (model::constitutive_values' g0_power) of a lane group, through its memo.
struct RememberedG0Power {
  PowMemo& memo;
  Cells operator()(const Cells& a) const {
    static_assert(lane_count == 4, "PowMemo holds four lanes");
    Cells r;
    for (int l = 0; l < lane_count; ++l) {
      if (a.v[l] == memo.argument[l]) {
        r.v[l] = memo.value[l];
      } else {
        r.v[l] = std::pow(a.v[l], model::detail::g0_exponent);
        memo.argument[l] = a.v[l];
        memo.value[l] = r.v[l];
      }
    }
    return r;
  }
};

template <class S> struct CellClosure {
  S p, c, mu, lambda, kappa, loss;
};

/// Whether evaluate() calls the model (and so requires 0 < nu < nu_max).
bool needs_model(const PhysicsSettings& s, bool need_transport) {
  const Terms& terms = s.terms;
  const bool ideal = s.eos == EquationOfState::ideal_gas;
  const bool transport = need_transport && (terms.shear_viscosity || terms.bulk_viscosity || terms.conduction);
  return (terms.pressure && !ideal) || terms.collisional_loss || transport;
}

/// The `transport_coefficients` artificial dissipation (ArtificialDissipation, operator.hpp),
/// added to the cell's mu and kappa.
template <class S> void add_artificial_transport(const PhysicsSettings& s, const S& n, double h, CellClosure<S>& r) {
  const Terms& terms = s.terms;
  const S x = volume_fraction(n) / s.artificial.volume_fraction;
  const S x2 = x * x;
  const S weight = n * h * r.c / (1.0 + x2 * x2);
  if (terms.shear_viscosity) r.mu += s.artificial.viscosity * weight;
  if (terms.conduction) r.kappa += s.artificial.conductivity * weight;
}

// One fused evaluation of the model per cell (model::constitutive_values: G once), and only
// when some enabled term needs it.
template <class S, class Power = model::G0Power>
CellClosure<S> evaluate(const PhysicsSettings& s, const S& n, const S& T, double h, bool need_transport,
                        const Power& g0_power = {}) {
  using std::sqrt;
  CellClosure<S> r{0.0, 0.0, 0.0, 0.0, 0.0, 0.0};
  const Terms& terms = s.terms;
  const bool ideal = s.eos == EquationOfState::ideal_gas;
  if (ideal && terms.pressure) {
    if constexpr (std::is_arithmetic_v<S>) {
      if (!(T >= 0.0)) model::detail::domain_failure("ideal gas", "T", T, "T >= 0");
    }
    r.p = n * T;
    r.c = sqrt(5.0 / 3.0 * T);
  }
  if (!needs_model(s, need_transport)) return r;
  const model::ConstitutiveValues<S> m = model::constitutive_values(n, T, s.e, s.transport, g0_power);
  if (terms.pressure && !ideal) {
    r.p = m.pressure;
    r.c = m.sound_speed;
  }
  if (terms.collisional_loss) r.loss = m.collisional_loss;
  if (!need_transport) return r;
  if (terms.shear_viscosity) r.mu = m.shear_viscosity;
  if (terms.bulk_viscosity) r.lambda = m.bulk_viscosity;
  if (terms.conduction) r.kappa = m.thermal_conductivity;
  if (effective_artificial_form(s) == ArtificialForm::transport_coefficients) add_artificial_transport(s, n, h, r);
  return r;
}

/// A lane group, with everything inlined (flatten): the model's values that the settings and
/// need_transport leave unused are then never computed (transport coefficients in the
/// hyperbolic stages of a split step).
template <bool need_transport>
[[gnu::flatten]] CellClosure<Cells> evaluate_cells(const PhysicsSettings& s, const Cells& n, const Cells& T, double h,
                                                   PowMemo& memo) {
  return evaluate(s, n, T, h, need_transport, RememberedG0Power{memo});
}

/// The closure of runs of cells: the primitives n and T it reads, the closure arrays and pow
/// memo it writes (ghosts included in the arrays).
struct ClosureRun {
  const PhysicsSettings& settings;
  double h;
  bool need_transport, model_needed, e_valid;
  const double* wn;
  const double* wT;
  Operator::Closure& closure;
  double* pow_argument;
  double* pow_value;

  void store(std::ptrdiff_t c, const CellClosure<double>& r) const {
    Operator::Closure& cl = closure;
    cl.p[c] = r.p;
    cl.c[c] = r.c;
    cl.chi[c] = wT[c] > 0.0 ? r.p / (wn[c] * wT[c]) : 1.0;
    cl.mu[c] = r.mu;
    cl.lambda[c] = r.lambda;
    cl.kappa[c] = r.kappa;
    cl.loss[c] = r.loss;
  }

  /// Every lane's state in the model's domain (where the settings need the model).
  bool in_domain(const Cells& n, const Cells& T) const {
    bool valid = e_valid;
    for (int l = 0; l < lane_count; ++l) {
      const double nu = volume_fraction(n.v[l]);
      valid = valid && T.v[l] >= 0.0 && (!model_needed || (nu > 0.0 && nu < nu_max));
    }
    return valid;
  }

  /// The lane group of cells c .. c + lanes - 1; a short group repeats its last cell.
  void load(std::ptrdiff_t c, int lanes, Cells& n, Cells& T, PowMemo& memo) const {
    if (lanes == lane_count) {  // whole-group copies (no scalar stores read back as pairs)
      n.v = load_lanes<Cells::Vector>(wn + c);
      T.v = load_lanes<Cells::Vector>(wT + c);
      std::copy_n(pow_argument + c, lane_count, memo.argument);
      std::copy_n(pow_value + c, lane_count, memo.value);
      return;
    }
    for (int l = 0; l < lane_count; ++l) {
      const std::ptrdiff_t cell = c + std::min(l, lanes - 1);
      n.v[l] = wn[cell];
      T.v[l] = wT[cell];
      memo.argument[l] = pow_argument[cell];
      memo.value[l] = pow_value[cell];
    }
  }

  void store(std::ptrdiff_t c, int lanes, const Cells& n, const Cells& T, const PowMemo& memo,
             const CellClosure<Cells>& r) const {
    if (lanes == lane_count) {  // whole vectors: per lane the arithmetic of `store`
      Operator::Closure& cl = closure;
      std::copy_n(memo.argument, lane_count, pow_argument + c);
      std::copy_n(memo.value, lane_count, pow_value + c);
      store_lanes(cl.p.data() + c, r.p.v);
      store_lanes(cl.c.data() + c, r.c.v);
      store_lanes(cl.chi.data() + c, T.v > 0.0 ? r.p.v / (n.v * T.v) : Cells::Vector{} + 1.0);
      store_lanes(cl.mu.data() + c, r.mu.v);
      store_lanes(cl.lambda.data() + c, r.lambda.v);
      store_lanes(cl.kappa.data() + c, r.kappa.v);
      store_lanes(cl.loss.data() + c, r.loss.v);
      return;
    }
    for (int l = 0; l < lanes; ++l) {
      pow_argument[c + l] = memo.argument[l];
      pow_value[c + l] = memo.value[l];
    }
    for (int l = 0; l < lanes; ++l)
      store(c + l, CellClosure<double>{r.p.v[l], r.c.v[l], r.mu.v[l], r.lambda.v[l], r.kappa.v[l], r.loss.v[l]});
  }

  /// Cells first .. end - 1, lane group by lane group.
  void evaluate_run(std::ptrdiff_t first, std::ptrdiff_t end) const {
    for (std::ptrdiff_t c = first; c < end; c += lane_count) {
      const int lanes = static_cast<int>(std::min<std::ptrdiff_t>(lane_count, end - c));
      Cells n, T;
      PowMemo memo;
      load(c, lanes, n, T, memo);
      if (!in_domain(n, T)) {  // cell by cell: the first cell outside the domain throws
        for (int l = 0; l < lanes; ++l) store(c + l, evaluate(settings, wn[c + l], wT[c + l], h, need_transport));
        continue;
      }
      const CellClosure<Cells> r = need_transport ? evaluate_cells<true>(settings, n, T, h, memo)
                                                  : evaluate_cells<false>(settings, n, T, h, memo);
      store(c, lanes, n, T, memo, r);
    }
  }
};

/// Calls run(row) for every row, on the threads if `threaded`. Rows of x; dynamic scheduling:
/// on a shared machine a thread that is held up does not hold up the other. An exception must
/// not leave an OpenMP region: the first failure is kept and rethrown.
template <class Run> void for_rows(int rows, bool threaded, const Run& run) {
  if (!threaded) {
    for (int row = 0; row < rows; ++row) run(row);
    return;
  }
  std::exception_ptr failure;
#pragma omp parallel for schedule(dynamic, 16)
  for (int row = 0; row < rows; ++row) {
    try {
      run(row);
    } catch (...) {
#pragma omp critical(shaker_closure_failure)
      if (!failure) failure = std::current_exception();
    }
  }
  if (failure) std::rethrow_exception(failure);
}
}  // namespace

void Operator::update_primitives_and_closure(const State& U, bool need_transport) {
  const Grid& g = grid_;
  transport_evaluated_ = need_transport;
  const ClosureRun closure{settings_,
                           g.h,
                           need_transport,
                           needs_model(settings_, need_transport),
                           settings_.e >= 0.0 && settings_.e <= 1.0,
                           w_[0].data(),
                           w_[4].data(),
                           closure_,
                           pow_argument_.data(),
                           pow_value_.data()};
  const bool x_by_rows = x_ghosts_by_rows();
  // One contiguous run of interior cells (its x ghosts, where x is periodic in this process,
  // copied while the row is in cache; the other ghosts afterwards): the primitives
  // (what to_primitive computes, as one vectorisable loop), then the closure lane group by
  // lane group.
  const int length = g.row_length();
  for_rows(g.interior_rows(), g.threaded(), [&](int row) {
    const std::ptrdiff_t first = g.row_start(row);
    to_primitives(U, w_, first, length);
    closure.evaluate_run(first, first + length);
    if (x_by_rows) copy_row_to_x_ghosts(first);
  });
}

}  // namespace shaker::continuum
