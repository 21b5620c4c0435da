// Keys of the continuum solver (docs/models.md, "The continuum model").
#include "common/config.hpp"

namespace shaker::config {

std::vector<ParameterSpec> continuum_parameters() {
  return {
      integer("continuum.dimension", 1, closed(1, 3), "1: vertical column; 3: periodic x, y").in("-"),
      real("continuum.cell_size", 0.1, positive(10.0), "grid spacing in every direction").in("sigma"),
      real("continuum.box_width", 11.0, Range{1.0, 1e4, true, false},
           "periodic box edge in x (3D)").in("sigma"),
      real("continuum.box_depth", 0.0, closed(0.0, 1e4),
           "periodic box edge in y (3D); 0 (the default): equal to continuum.box_width, a square "
           "box. Otherwise a whole number (at least 4) of continuum.cell_size").in("sigma"),
      real("continuum.ceiling", 80.0, positive(1e5), "height of the ceiling above the plate").in("sigma"),
      real("continuum.initial_volume_fraction", 0.5, Range{0.0, 0.65, true, true},
           "volume fraction of the initial flat layer (below nu_max = 0.65)").in("1"),
      text("continuum.transport", "full", {"paper", "full"},
           "paper: 1/G terms dropped plus low-density artificial dissipation; full: all terms").in("-"),
      text("continuum.limiter", "mc", {"minmod", "mc", "van_leer", "none", "first_order"},
           "slope limiter; none = unlimited central slopes (smooth-solution verification only); "
           "first_order = zero slopes (Godunov)").in("-"),
      text("continuum.riemann", "hllc", {"hllc", "hll"}, "approximate Riemann solver").in("-"),
      real("continuum.cfl", 0.4, positive(1.0), "Courant number of each forward-Euler stage of the adaptive step").in("1"),
      real("continuum.perturbation", 1e-3, closed(0.0, 0.5),
           "3D: relative amplitude of the seeded random perturbation of the initial layer").in("1"),
      real("continuum.initial_temperature", 1e-2, positive(1e6),
           "temperature of the initial layer and background gas").in("g sigma"),
      real("continuum.background_volume_fraction", 1e-5, Range{0.0, 0.1, true, false},
           "volume fraction of the dilute gas above the initial layer").in("1"),
      integer("continuum.integrator_order", 2, closed(2, 3), "SSP Runge-Kutta order (2 or 3)").in("-"),
      integer("continuum.integrator_stages", 2, closed(2, 10),
              "order 2: stages s of SSP-RK(s,2) (2 = Heun); each stage is a forward-Euler step "
              "at continuum.cfl, so the step grows as s - 1. Order 3 (Shu-Osher) takes only 2").in("-"),
      real("continuum.diffusion_number", 0.8, positive(1.0),
           "time step as a fraction of the forward-Euler diffusive limit h^2 / (2 dim D)").in("1"),
      text("continuum.diffusion_integrator", "auto", {"auto", "explicit", "rkl2", "implicit", "implicit_extrapolated"},
           "diffusive terms: explicit in the SSP-RK step, or Strang-split RKL2 super time "
           "stepping, or Strang-split backward Euler (Eigen sparse; first order in time), or that "
           "Richardson-extrapolated to second order (two half steps against one whole, 3 solves); "
           "auto = implicit_extrapolated for full transport (plain backward Euler's time error "
           "exceeds the base case's grid uncertainty at cell 0.1 in 6 of 9 quantities), "
           "explicit for paper").in("-"),
      text("continuum.wall_stress", "mirror", {"mirror", "second_order"},
           "normal viscous stress at the walls: mirror = the mirror ghost's (first order where "
           "n' or u_z'' is not zero at the wall); second_order = coefficients extrapolated to the "
           "wall and u_z' = m' / n with m = n u_z, m' = (7 m_0 - m_1) / (2 h) (implicit diffusion: "
           "m_1 from the step's start)").in("-"),
      real("continuum.temperature_floor", 1e-12, positive(1.0),
           "lowest temperature; every raise to it is counted and reported").in("g sigma"),
      text("continuum.artificial_dissipation", "auto",
           {"auto", "none", "transport_coefficients", "second_difference", "von_neumann_richtmyer"},
           "artificial dissipation in the dilute regions, each weighted by s(nu) = 1 / (1 + (nu / "
           "nu_art)^4): transport_coefficients adds to mu and kappa; second_difference diffuses "
           "every conserved variable with D = coefficient * h (|u_n| + c) s; von_neumann_richtmyer "
           "adds q = coefficient * n du^2 s to the pressure of a face in compression; auto = "
           "transport_coefficients with paper transport, none with full (docs/models.md)").in("-"),
      real("continuum.artificial_viscosity", 0.5, at_least(0.0, 100.0),
           "coefficient of the artificial dissipation: mu_art = coefficient * n h c s(nu) "
           "(transport_coefficients), the second difference's or the von Neumann-Richtmyer "
           "pressure's coefficient").in("1"),
      real("continuum.artificial_conductivity", 0.5, at_least(0.0, 100.0),
           "transport_coefficients: kappa_art = coefficient * n h c s(nu)").in("1"),
      real("continuum.artificial_volume_fraction", 0.01, positive(0.65),
           "nu_art, the volume fraction below which artificial dissipation acts").in("1"),
      text("continuum.plate_energy", "adiabatic", {"adiabatic", "inelastic"},
           "energy the plate takes from the gas: adiabatic = none (dT/dz = 0, as the paper); "
           "inelastic = (1 - e^2) n_w T sqrt(T / (2 pi)) per unit area, n_w = p / T, the loss of "
           "a gas bouncing off a wall with the particles' restitution").in("-"),
      text("continuum.ceiling_energy", "adiabatic", {"adiabatic", "inelastic"},
           "the same for the ceiling").in("-"),
      real_list("continuum.field_phases", {}, Range{0.0, 1.0, false, true},
                "3D only: phases f t of the last cycle (or of continuum.field_cycles) whose full fields are written "
                "(RUN.fields.h5 + RUN.fields.xdmf), each a stored phase k / run.phases_per_cycle, "
                "at most once").in("1 (f t)"),
      real_list("continuum.field_cycles", {}, Range{-1e9, 1e9, false, false},
                "3D only: the cycles of the run (from 0, transient included; negative from the end, "
                "-1 the last) in which continuum.field_phases are written, each at most once, so that ParaView can "
                "animate the run; empty: the last cycle").in("cycles"),
  };
}

}  // namespace shaker::config
