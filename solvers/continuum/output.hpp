#pragma once
// What a continuum run reports: horizontally averaged profiles in the lab frame (the MD
// schema: z_lab = z + plate_z(t), u_lab = u_z + V_p(t)), integral diagnostics for the time
// series, and for 3D full fields in HDF5 with an XDMF sidecar for ParaView.
#include <filesystem>
#include <vector>

#include "common/profile.hpp"
#include "continuum/time_integrator.hpp"

namespace shaker::continuum {

Profile horizontal_profile(const TimeIntegrator& solver, const ShakerKinematics& shaker);

struct Diagnostics {
  double mass = 0, center_of_mass = 0;  ///< per unit plate area; height in the lab frame
  double kinetic = 0, thermal = 0, potential = 0;  ///< lab frame, per unit plate area
  double loss_rate = 0;                 ///< collisional loss per unit area and time
};
Diagnostics diagnostics(const TimeIntegrator& solver, const ShakerKinematics& shaker);

struct FieldSnapshot {
  double time = 0, phase = 0;
  std::vector<double> n, ux, uy, uz, T;  ///< interior cells, x fastest, lab-frame u_z
};
FieldSnapshot snapshot(const TimeIntegrator& solver, const ShakerKinematics& shaker);
/// Writes fields.h5 and its .xdmf sidecar atomically.
void write_fields(const std::filesystem::path& h5_path, const Grid& grid,
                  const std::vector<FieldSnapshot>& snapshots);

}  // namespace shaker::continuum
