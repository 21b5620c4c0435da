// Volume sources: gravity and the frame force of the oscillating container (body force per
// unit mass -g (1 + Gamma cos(omega t)) in z), the collisional energy loss gamma of the
// model, the inelastic walls' energy loss, and the optional external (manufactured) source.
#include <cmath>

#include "continuum/halo.hpp"
#include "continuum/operator.hpp"

namespace shaker::continuum {

double Operator::body_force(double t) const {
  double g = 0.0;
  if (settings_.terms.gravity) g -= gravity;
  if (settings_.terms.frame_force) g -= settings_.shaker.acceleration(t);
  return g;
}

void Operator::add_sources(double t, const State& U, State& dUdt) {
  const Grid& g = grid_;
  const double force = body_force(t);
  const bool loss = settings_.terms.collisional_loss;
  const bool external = static_cast<bool>(external_source);
  double body = 0.0, lost = 0.0;
  const double* N = U.q[density].data();
  const double* Mz = U.q[momentum_z].data();
  const double* gamma = closure_.loss.data();
  double* dMz = dUdt.q[momentum_z].data();
  double* dE = dUdt.q[energy].data();
  // Cells first .. first + count - 1 (contiguous), summed in storage order.
  const auto run = [&](std::ptrdiff_t first, std::ptrdiff_t count, double& body_sum, double& lost_sum) {
    for (std::ptrdiff_t c = first; c < first + count; ++c) {
      dMz[c] += N[c] * force;
      dE[c] += Mz[c] * force;
      body_sum += Mz[c] * force;
      if (loss) {
        dE[c] -= gamma[c];
        lost_sum += gamma[c];
      }
    }
  };
  if (g.dimension != 3) {
    run(g.row_start(0), g.row_length(), body, lost);
  } else {
#pragma omp parallel for schedule(static) reduction(+ : body, lost) if (g.nz > 1 && g.threaded() && !external)
    for (int k = 0; k < g.nz; ++k)
      for (int j = 0; j < g.ny; ++j) run(g.index(0, j, k), g.nx, body, lost);
  }
  lost += add_wall_energy_losses(dUdt);
  // The external source is a user callback: it stays serial.
  if (external) {
    const int i0 = halo_ ? halo_->block().i0 : 0, j0 = halo_ ? halo_->block().j0 : 0;
    for (int k = 0; k < g.nz; ++k)
      for (int j = 0; j < g.ny; ++j)
        for (int i = 0; i < g.nx; ++i) {
          const std::ptrdiff_t c = g.index(i, j, k);
          double extra[variable_count] = {0, 0, 0, 0, 0};
          const double x = g.dimension == 3 ? g.center(i0 + i) : 0.0;
          const double y = g.dimension == 3 ? g.center(j0 + j) : 0.0;
          external_source(t, x, y, g.center(k), extra);
          for (int v = 0; v < variable_count; ++v) dUdt.q[v][c] += extra[v];
        }
  }
  // Per unit plate area: a cell holds h / (nx ny) of the column (1D: nx = ny = 1), nx ny
  // those of the whole box (a rank's share is summed over the ranks with its budget).
  const double per_area = g.h / plate_columns();
  source_power_ = SourcePower{body * per_area, lost * per_area};
}

// A Maxwellian gas beside a flat wall hits it n_w sqrt(T / (2 pi)) times per unit area and
// time; each bounce keeps e^2 of the normal kinetic energy, and <v_z^2> over the hits is 2 T,
// so the wall takes Q = (1 - e^2) n_w T sqrt(T / (2 pi)). The density at contact n_w = p / T
// (the contact theorem of hard spheres at a hard wall) carries the dense gas's enhancement.
double Operator::add_wall_energy_losses(State& dUdt) const {
  const Grid& g = grid_;
  if (g.z_boundary != ZBoundary::walls) return 0.0;
  const double one_minus_e2 = 1.0 - settings_.e * settings_.e;
  double lost = 0.0;
  for (int k : {0, g.nz - 1}) {
    if ((k == 0 ? settings_.plate_energy : settings_.ceiling_energy) != WallEnergy::inelastic) continue;
    for (int j = 0; j < g.ny; ++j)
      for (int i = 0; i < g.nx; ++i) {
        const std::ptrdiff_t c = g.index(i, j, k);
        const double T = w_[4][c], n = w_[0][c];
        const double contact = settings_.terms.pressure && T > 0.0 ? closure_.p[c] / T : n;
        const double loss = one_minus_e2 * contact * T * std::sqrt(T / (2.0 * pi)) / g.h;
        dUdt.q[energy][c] -= loss;
        lost += loss;
      }
    if (g.nz == 1) break;
  }
  return lost;
}

}  // namespace shaker::continuum
