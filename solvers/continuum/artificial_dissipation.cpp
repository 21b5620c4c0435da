// The face-based artificial dissipation forms (operator.hpp, ArtificialForm): a second
// difference of every conserved variable, and a von Neumann-Richtmyer pressure in compression.
// Both act on the faces of every flux direction, read the primitives and sound speed with their
// ghosts (mirror at walls, so no mass or energy crosses a wall), and leave total mass and
// energy unchanged. Serial: these forms are choices for the sensitivity study, not the
// production path (the default forms live in the closure, transport.cpp).
#include <algorithm>
#include <array>
#include <cmath>

#include "continuum/operator.hpp"

namespace shaker::continuum {

namespace {

using Conserved = std::array<double, variable_count>;

/// The density switch s(nu) that confines the dissipation to the dilute regions.
double density_switch(double n, double threshold) {
  const double x = volume_fraction(n) / threshold, x2 = x * x;
  return 1.0 / (1.0 + x2 * x2);
}

Conserved conserved_at(const std::array<std::vector<double>, variable_count>& w, std::ptrdiff_t c) {
  const double n = w[0][c], ux = w[1][c], uy = w[2][c], uz = w[3][c];
  return {n, n * ux, n * uy, n * uz, n * (0.5 * (ux * ux + uy * uy + uz * uz) + 1.5 * w[4][c])};
}

/// The cells on either side of one face, and the direction the face is normal to.
struct Face {
  std::ptrdiff_t left, right;
  int direction;
};

/// Flux (in the direction's positive sense) of the second-difference form; returns D.
double second_difference_flux(const std::array<std::vector<double>, variable_count>& w,
                              const std::vector<double>& c, const ArtificialDissipation& a, double h,
                              const Face& f, Conserved& flux) {
  const int un = 1 + f.direction;
  const double speed = std::max(std::abs(w[un][f.left]) + c[f.left], std::abs(w[un][f.right]) + c[f.right]);
  const double D = a.viscosity * h * speed * density_switch(0.5 * (w[0][f.left] + w[0][f.right]), a.volume_fraction);
  const Conserved UL = conserved_at(w, f.left), UR = conserved_at(w, f.right);
  for (int v = 0; v < variable_count; ++v) flux[v] = -D * (UR[v] - UL[v]) / h;
  return D;
}

/// Flux of the von Neumann-Richtmyer pressure (zero where the face expands); returns its
/// diffusivity 2 C h |du|.
double von_neumann_richtmyer_flux(const std::array<std::vector<double>, variable_count>& w,
                                  const ArtificialDissipation& a, double h, const Face& f, Conserved& flux) {
  flux.fill(0.0);
  const int un = 1 + f.direction;
  const double du = w[un][f.right] - w[un][f.left];
  if (!(du < 0.0)) return 0.0;
  const double n = 0.5 * (w[0][f.left] + w[0][f.right]);
  const double q = a.viscosity * n * du * du * density_switch(n, a.volume_fraction);
  flux[un] = q;
  flux[energy] = q * 0.5 * (w[un][f.left] + w[un][f.right]);
  return 2.0 * a.viscosity * h * std::abs(du);
}

}  // namespace

void Operator::add_artificial_fluxes(State& dUdt) {
  artificial_diffusivity_ = 0.0;
  const ArtificialForm form = effective_artificial_form(settings_);
  if (form != ArtificialForm::second_difference && form != ArtificialForm::von_neumann_richtmyer) return;
  const Grid& g = grid_;
  const ArtificialDissipation& a = settings_.artificial;
  const double inv_h = 1.0 / g.h;
  const int n_cells[3] = {g.nx, g.ny, g.nz};
  for (int d = g.first_direction(); d < 3; ++d) {
    const std::ptrdiff_t s = g.stride(d);
    const int length = n_cells[d];
    // Pencils along d: every (i, j, k) with the d index 0.
    for (int k = 0; k < (d == 2 ? 1 : g.nz); ++k)
      for (int j = 0; j < (d == 1 ? 1 : g.ny); ++j)
        for (int i = 0; i < (d == 0 ? 1 : g.nx); ++i) {
          const std::ptrdiff_t first = g.index(i, j, k);
          for (int face = 0; face <= length; ++face) {
            const Face f{first + (face - 1) * s, first + face * s, d};
            Conserved flux;
            const double D = form == ArtificialForm::second_difference
                                 ? second_difference_flux(w_, closure_.c, a, g.h, f, flux)
                                 : von_neumann_richtmyer_flux(w_, a, g.h, f, flux);
            artificial_diffusivity_ = std::max(artificial_diffusivity_, D);
            for (int v = 0; v < variable_count; ++v) {
              if (face > 0) dUdt.q[v][f.left] -= flux[v] * inv_h;
              if (face < length) dUdt.q[v][f.right] += flux[v] * inv_h;
            }
          }
        }
  }
}

}  // namespace shaker::continuum
