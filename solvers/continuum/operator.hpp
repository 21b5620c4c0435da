#pragma once
// The right-hand side dU/dt = -div F(U) + S(U, t) of the Jenkins–Richman equations
// (docs/models.md, "The continuum model") on a Grid, callable on its own: every physical term can be
// switched off and an external source per cell and time can be added (the manufactured-
// solution harness needs both). Frame: the container's; walls at z = 0 and z = height.
#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "common/granular_model.hpp"
#include "common/shaker_kinematics.hpp"
#include "continuum/grid.hpp"
#include "continuum/state.hpp"

namespace shaker::continuum {

enum class EquationOfState { granular, ideal_gas };  ///< ideal_gas: p = n T, gamma = 5/3
/// `none`: unlimited central slopes, for verifying smooth solutions (limiters clip smooth
/// extrema to first order, which caps the Linf order near 1.3). `first_order`: zero slopes
/// everywhere (Godunov's scheme), the most dissipative reconstruction, for judging how much
/// the result owes to the slopes near vacuum.
enum class Limiter { minmod, mc, van_leer, none, first_order };
enum class RiemannSolver { hllc, hll };              ///< hll is the simple reference

/// Which terms enter the operator. `advection` is the whole inviscid (Riemann) flux;
/// `pressure` = false makes that flux pressureless.
struct Terms {
  bool advection = true, pressure = true;
  bool shear_viscosity = true, bulk_viscosity = true, conduction = true;
  bool collisional_loss = true, gravity = true, frame_force = true;
  bool artificial_dissipation = true;  ///< the form of PhysicsSettings::artificial, if any
};

/// Which artificial dissipation the operator adds in the dilute regions (docs/models.md,
/// "Artificial dissipation"). Every form is weighted by the density switch
/// s(nu) = 1 / (1 + (nu / volume_fraction)^4), scales with the cell size h, and vanishes with
/// refinement.
///  - transport_coefficients: mu += viscosity * n h c s, kappa += conductivity * n h c s;
///  - second_difference: every conserved variable diffuses with D = viscosity * h (|u_n| + c) s
///    across each face (a scalar, Lax-Friedrichs-like second difference);
///  - von_neumann_richtmyer: a face in compression (u_n jumps down across it by du > 0) carries
///    the extra pressure q = viscosity * n du^2 s in its normal momentum and q u_n in its energy
///    flux.
/// `automatic` is transport_coefficients with paper transport and none with full transport.
enum class ArtificialForm { automatic, none, transport_coefficients, second_difference, von_neumann_richtmyer };

struct ArtificialDissipation {
  ArtificialForm form = ArtificialForm::automatic;
  double viscosity = 0.5;
  double conductivity = 0.5;
  double volume_fraction = 0.01;
};

/// The energy a wall takes from the gas beside it. `adiabatic`: none (zero heat flux, as in the
/// paper). `inelastic`: the loss of a Maxwellian gas bouncing off a flat wall with the
/// particles' restitution e, Q = (1 - e^2) n_w T sqrt(T / (2 pi)) per unit area, n_w = p / T
/// the contact density (sources.cpp).
enum class WallEnergy { adiabatic, inelastic };

/// The walls' normal viscous stress. `mirror`: the mirror ghost's, the wall cell's coefficients
/// and the slope 2 u_0 / h, first order where n' or u_z'' is not zero at the wall (every layer
/// under gravity). `second_order`: the coefficients extrapolated linearly to the wall and
/// u_z' = m' / n there, m = n u_z, from the cells' averages (viscous_flux.cpp,
/// wall_normal_stress; docs/models.md); the implicit diffusion takes m_1 from the step's start
/// (implicit_diffusion.cpp, wall_row).
enum class WallStress { mirror, second_order };

struct PhysicsSettings {
  EquationOfState eos = EquationOfState::granular;
  double e = 0.9;  ///< the continuum's restitution coefficient
  model::Transport transport = model::Transport::paper;
  ArtificialDissipation artificial;
  Limiter limiter = Limiter::mc;
  RiemannSolver riemann = RiemannSolver::hllc;
  WallStress wall_stress = WallStress::mirror;
  WallEnergy plate_energy = WallEnergy::adiabatic, ceiling_energy = WallEnergy::adiabatic;
  Terms terms;
  ShakerKinematics shaker{3.0, 0.095};
};

/// The artificial dissipation in effect (`automatic` resolved), none if its term is off.
ArtificialForm effective_artificial_form(const PhysicsSettings& s);

/// Optional source added per cell: (t, x, y, z, out[variable_count]) adds to out.
/// In 1D x = y = 0. Used by the manufactured-solution harness.
using ExternalSource = std::function<void(double, double, double, double, double*)>;

/// What the operator evaluates: everything, or the parts an operator split separates.
enum class Part { all, hyperbolic_and_sources, diffusive };

class Halo;  // halo.hpp

/// The part of a flux sweep along direction d that belongs to planes k0 .. k1 - 1. A sweep's
/// pencils run along d, indexed (a, b) across it, b being the plane for x and y and the row
/// for z; faces 0 .. length along each pencil. Along x and y: the pencils of those planes, every
/// face; along z: every pencil, faces k0 .. k1 - 1 (the top face nz too with the last plane).
struct SlabSweep {
  int b_first, b_count, f_begin, f_end;
};
inline SlabSweep slab_sweep(const Grid& g, int d, int k0, int k1) {
  if (d == 2) return {0, g.ny, k0, k1 < g.nz ? k1 : g.nz + 1};
  return {k0, k1 - k0, 0, (d == 0 ? g.nx : g.ny) + 1};
}

class Operator {
 public:
  /// Planes of a slab: a 3D box's fluxes are added a slab at a time (rhs). Eight planes of
  /// the 16 fields the fluxes touch fit the 1 MB L2 cache of a core for blocks up to about
  /// 30 x 30 columns.
  static constexpr int slab_planes = 8;

  /// `grid` is the whole domain, or with a `halo` this rank's block of the decomposed box
  /// (halo->local()): ghosts in x and y are then exchanged with the neighbouring ranks and
  /// step limits and energy sums are taken over the whole box.
  Operator(const Grid& grid, const PhysicsSettings& settings, std::shared_ptr<const Halo> halo = nullptr);

  /// dUdt = L(U, t). Only U's interior cells are read: the fluxes take their neighbours from
  /// the primitives and closure, whose ghosts the evaluation fills (walls, periodic or the
  /// halo's exchange). Throws DomainError (constitutive function outside its domain) on a
  /// broken state.
  void rhs(double t, const State& U, State& dUdt, Part part = Part::all);

  /// Largest stable explicit steps at the last evaluated state (call after rhs):
  /// advective cfl * h / max(sum_d |u_d| + c), and FE diffusive h^2 / (2 dim D_max).
  double advective_step(double cfl) const;
  double diffusive_step() const;
  /// Largest stable forward-Euler step of the explicit artificial dissipation (second_difference,
  /// von_neumann_richtmyer) at the last rhs, h^2 / (2 dim D_max); infinite without it.
  double artificial_step() const;

  /// Evaluates primitives and the closure at U, ghosts included (with the transport
  /// coefficients unless need_transport is false), without fluxes.
  void prepare(const State& U, bool need_transport = true) { evaluate_closure(U, need_transport); }

  /// Gravity plus frame force per unit mass at time t (z component).
  double body_force(double t) const;

  const Grid& grid() const { return grid_; }
  /// The decomposition, or null when this process holds the whole domain.
  const Halo* halo() const { return halo_.get(); }
  const std::shared_ptr<const Halo>& shared_halo() const { return halo_; }
  /// Columns of the whole domain (1 for a column): amounts per unit plate area divide by them.
  double plate_columns() const;
  PhysicsSettings& settings() { return settings_; }
  const PhysicsSettings& settings() const { return settings_; }
  ExternalSource external_source;  ///< empty: none

  // Closure of the last evaluation, per cell (ghosts included).
  struct Closure {
    std::vector<double> p, c, chi, mu, lambda, kappa, loss;  ///< chi = p / (n T), loss: gamma
  };
  const Closure& closure() const { return closure_; }

  /// Energy sources of the last rhs that included them, integrated over the domain (with a
  /// halo: over this rank's block, to be summed over the ranks) per unit plate area: power of the body force (gravity + frame force) and the collisional loss rate.
  struct SourcePower {
    double body = 0, loss = 0;
  };
  const SourcePower& source_power() const { return source_power_; }
  const std::array<std::vector<double>, variable_count>& primitives() const { return w_; }

 private:
  /// The primitives and closure of the interior, then copied to the ghosts; with a halo every
  /// rank fails alike (DomainError with the first failing rank's message) if any rank fails.
  void evaluate_closure(const State& U, bool need_transport);
  void update_primitives_and_closure(const State& U, bool need_transport);  // transport.cpp, primitives.cpp
  void copy_closure_to_ghosts();                                             // boundary.cpp
  /// The fields whose ghosts are filled: the primitives, then the closure values the fluxes
  /// read beside a cell (boundary.cpp).
  std::array<std::vector<double>*, variable_count + 6> ghosted_fields();
  /// Whether x is periodic within this process (no halo, or one rank along x), so that the
  /// closure's row loop fills each row's x ghosts while the row is in cache.
  bool x_ghosts_by_rows() const;
  /// Copies row `first`'s periodic x ghosts of the ghosted fields (its interior cells filled).
  void copy_row_to_x_ghosts(std::ptrdiff_t first);                          // boundary.cpp
  /// The faces of planes k0 .. k1 - 1 (along z: faces k0 .. k1 - 1, and nz with the last).
  void add_inviscid_fluxes(State& dUdt, int k0, int k1);                     // inviscid_sweep.cpp
  void add_diffusive_fluxes(State& dUdt, int k0, int k1);                    // viscous_flux.cpp
  /// The face-based artificial dissipation forms (artificial_dissipation.cpp).
  void add_artificial_fluxes(State& dUdt);
  /// The inelastic walls' energy loss, added to dUdt and to the loss sum (sources.cpp).
  double add_wall_energy_losses(State& dUdt) const;
  void add_sources(double t, const State& U, State& dUdt);                   // sources.cpp

  Grid grid_;
  PhysicsSettings settings_;
  std::shared_ptr<const Halo> halo_;
  std::array<std::vector<double>, variable_count> w_;  ///< n, ux, uy, uz, T
  Closure closure_;
  bool transport_evaluated_ = false;
  /// Per cell: the last argument of the closure's pow and its value (transport.cpp).
  std::vector<double> pow_argument_, pow_value_;
  SourcePower source_power_;
  double artificial_diffusivity_ = 0.0;  ///< largest D of the last add_artificial_fluxes
};

Limiter limiter_from_string(const std::string& name);          ///< throws InputError
RiemannSolver riemann_from_string(const std::string& name);    ///< throws InputError
ArtificialForm artificial_form_from_string(const std::string& name);  ///< throws InputError
WallEnergy wall_energy_from_string(const std::string& key, const std::string& name);  ///< throws InputError

}  // namespace shaker::continuum
