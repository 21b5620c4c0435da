#pragma once
// What a continuum run reports: horizontally averaged profiles in the lab frame (the MD
// schema: z_lab = z + plate_z(t), u_lab = u_z + V_p(t)), integral diagnostics for the time
// series, and for 3D full fields in HDF5 with an XDMF sidecar for ParaView (also lab frame).
#include <filesystem>
#include <vector>

#include "common/profile.hpp"
#include "continuum/time_integrator.hpp"

namespace shaker::continuum {

/// The scalars of a run that its outputs and checkpoints carry beside the state.
struct RunScalars {
  double time = 0, e = 0;  ///< e: the restitution in effect
  EnergyBudget budget;
  Counters counters;
};
/// What the outputs read of a run at one instant: the whole box (on a decomposed run, the
/// root's gathered copy) and its scalars.
struct BoxView {
  const Grid& grid;
  const State& state;
  RunScalars scalars;
};
/// The solver itself, on one process: nothing copied.
BoxView view_of(const TimeIntegrator& solver);

Profile horizontal_profile(const BoxView& box, const ShakerKinematics& shaker);
inline Profile horizontal_profile(const TimeIntegrator& solver, const ShakerKinematics& shaker) {
  return horizontal_profile(view_of(solver), shaker);
}
/// Container-frame energy per unit plate area: TimeIntegrator::total_energy of the box.
double total_energy(const BoxView& box);

struct Diagnostics {
  double mass = 0, center_of_mass = 0;  ///< per unit plate area; height in the lab frame
  double kinetic = 0, thermal = 0, potential = 0;  ///< lab frame, per unit plate area
  double loss_rate = 0;                 ///< collisional loss per unit area and time
};
Diagnostics diagnostics(const BoxView& box, const ShakerKinematics& shaker);
inline Diagnostics diagnostics(const TimeIntegrator& solver, const ShakerKinematics& shaker) {
  return diagnostics(view_of(solver), shaker);
}

/// The full fields at one instant, in the lab frame like the profiles: the cells sit at their
/// container-frame centres + plate_z, and u_z includes plate_v.
struct FieldSnapshot {
  double time = 0, phase = 0, plate_z = 0, plate_v = 0;
  std::int64_t cycle = 0;  ///< of the run's schedule, from 0
  std::vector<double> n, nu, ux, uy, uz, T;  ///< interior cells, x fastest, lab-frame u_z
};
FieldSnapshot snapshot(const BoxView& box, const ShakerKinematics& shaker, std::int64_t cycle);
/// Root attribute `kind` of the fields file: a reader of run files refuses it by this.
inline constexpr const char* fields_file_kind = "shaker continuum fields";
/// The fields file's group of snapshot s: snapshot_000, snapshot_001, ...
std::string fields_snapshot_group(std::size_t s);
/// Writes the fields file (h5_path) and its .xdmf sidecar atomically; the file's root carries
/// the run file's attributes, from `run` (docs/output-schema.md).
void write_fields(const std::filesystem::path& h5_path, const Grid& grid,
                  const std::vector<FieldSnapshot>& snapshots, const RunRecord& run);

}  // namespace shaker::continuum
