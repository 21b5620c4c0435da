#pragma once
// Manufactured-solution runs of the continuum solver: the solver integrates dU/dt = L(U) + S with S the cell average of the
// conservative-form source of mms_source.hpp, from the exact cell averages at t = 0, and the
// result at t_end is compared with the exact cell averages then.
//
// Boundaries: `walls` uses the solver's real (mirror) walls with the wall-compatible solution,
// whose even/odd symmetry about z = 0 and z = Lz makes the mirror ghosts exact; `periodic`
// uses the shifted (not wall-compatible) solution on a periodic column of height 2 Lz, which
// is a whole number of periods of every cos(j pi z / Lz + phase) in the solution.
//
// Initial state and reference are averaged with the 3-point Gauss rule of cell_average.hpp
// (error O(h^6)), so the measured error is the scheme's own; the source is averaged the same
// way, or (for 3D cost) from the centre values to O(h^4). The source's value at the centre
// alone would not do: its O(h^2) difference from the average adds to the scheme's own error
// (verification/README.md, "The 3D manufactured-solution study").
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "cell_average.hpp"
#include "continuum/time_integrator.hpp"
#include "support/convergence.hpp"
#include "support/error_table.hpp"
#include "mms_source.hpp"

namespace shaker::mms {

/// The five conservative components of a source (mass, momentum x, y, z, energy) in order.
inline std::array<double, 5> components(const Residual& r) {
  return {r.mass, r.momentum[0], r.momentum[1], r.momentum[2], r.energy};
}

/// How a run takes the cell average of the source (see CorrectedCentreSource).
enum class SourceRule { gauss_average, corrected_centre };

struct MmsCase {
  int dimension = 1;
  model::Transport transport = model::Transport::full;
  continuum::ZBoundary boundary = continuum::ZBoundary::walls;
  Terms terms;                 ///< time_derivative must stay on
  int cells_z = 40;            ///< cells across Lz (the periodic column has 2 cells_z)
  double t_end = 1.0;
  double fixed_dt = 0.0;       ///< > 0: constant step (temporal studies), else adaptive
  int rk_order = 3;            ///< SSP-RK2 or SSP-RK3
  double cfl = 0.4;
  continuum::DiffusionIntegrator diffusion = continuum::DiffusionIntegrator::explicit_rk;
  bool artificial_dissipation = false;  ///< `paper` variant only
  double e = 0.9;
  /// Source per cell: the Gauss cell average (3 points in 1D, 27 in 3D, O(h^6)) or the
  /// corrected centre value (one point per cell, O(h^4)).
  SourceRule source_rule = SourceRule::gauss_average;
  double velocity_amplitude = 0.3;     ///< ManufacturedSolution::U0
  int density_mode = 4;                ///< ManufacturedSolution::density_mode
  bool wall_gradients = false;         ///< ManufacturedSolution::wall_gradients
  continuum::WallStress wall_stress = continuum::WallStress::mirror;
};

/// The cell average of the source to O(h^4) from one evaluation per cell: the centre value
/// plus h^2 / 24 times its Laplacian, the Laplacian from central differences of the centre
/// values (one layer of cells beyond the grid, where the smooth solution is defined as well).
/// Every cell is evaluated at once when the time changes; the operator then asks for the cells
/// one by one (serially: it calls an external source outside its threads).
class CorrectedCentreSource {
 public:
  CorrectedCentreSource(const ManufacturedSolution& solution, const Physics& physics,
                        const Terms& terms, const continuum::Grid& g);
  /// The average over the cell whose centre is x (for a column, x[2] alone matters).
  Residual operator()(double t, const std::array<double, 3>& x);

 private:
  std::size_t slot(int i, int j, int k) const;  ///< padded indices, 0 is the layer outside
  const Residual& at(int i, int j, int k) const;
  void fill(double t);

  const ManufacturedSolution& solution_;
  const Physics& physics_;
  const Terms& terms_;
  const continuum::Grid& g_;
  int px_, py_;
  std::vector<Residual> centre_;
  double t_ = std::nan("");
};

/// The manufactured solution a case uses (wall-compatible with walls; 3D box 5 x 5 x 10).
ManufacturedSolution solution_for(const MmsCase& c);

/// Solver settings of a case: limiter none (smooth solution), solver terms mapped from the mms
/// switches (the solver's `advection` is the whole inviscid flux, so mms pressure alone runs
/// with the pressure flux, i.e. advection and pressure).
continuum::PhysicsSettings physics_for(const MmsCase& c);
Terms effective_terms(const MmsCase& c);  ///< the mms terms matching physics_for(c)

/// Numerical and exact primitive fields (n, ux, uy, uz, T) of every interior cell at t_end.
struct MmsResult {
  double h = 0.0;
  std::array<std::vector<double>, 5> numeric, exact;
  std::int64_t steps = 0;
};
MmsResult run_mms(const MmsCase& c);

inline const std::array<std::string, 5> field_names{"n", "ux", "uy", "uz", "T"};

/// Each term's part of the manufactured source: the root mean square of the source with that
/// term alone, per equation (mass, momentum x, y, z, energy), over the cell centres of the
/// case's grid at `samples` times in [0, t_end]. The terms' sources add up to the whole one;
/// `largest_sum_defect` is the largest |whole - sum of terms| over the sample, relative to the
/// largest |whole|.
struct TermShares {
  std::vector<std::string> terms;
  std::vector<std::array<double, 5>> rms;  ///< per term, per equation
  double largest_sum_defect = 0.0;
  /// rms of the term in `equation` over the sum of every term's rms there
  double share(std::size_t term, int equation) const;
};
inline const std::array<std::string, 5> equation_names{"mass", "momentum_x", "momentum_y",
                                                       "momentum_z", "energy"};
TermShares term_shares(const MmsCase& c, int samples = 3);
/// study,term,equation,rms,share: the rows of a *.term-shares.csv table (reports/
/// make_convergence_report.py), one per term and equation the term enters (rms > 0).
std::string term_shares_csv(const std::string& study, const TermShares& shares);

/// Runs the case on each resolution (cells_z) and adds L1, L2, Linf of every field
/// (ux, uy only in 3D) to `table` under `study`, level 0 the coarsest.
void spatial_study(const MmsCase& base, const std::vector<int>& cells_z, const std::string& study,
                   convergence::ErrorTable& table);

/// Runs the case with each fixed step and measures the difference from a reference run with
/// step reference_dt on the same grid (the spatial error cancels); adds the norms to `table`
/// with h = dt.
void temporal_study(const MmsCase& base, const std::vector<double>& dts, double reference_dt,
                    const std::string& study, convergence::ErrorTable& table);

}  // namespace shaker::mms
