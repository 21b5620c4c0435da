#pragma once
// Particle snapshots of an MD run (docs/output-schema.md, "Particle files"): every particle at
// chosen stored phases, all brought by free flight to the same time, lab frame. Written beside
// the run file in H5MD 1.1 (RUN.particles.h5, which a run may start from: md.initial_state =
// "file") and in extended XYZ (RUN.particles.xyz, for OVITO, ASE, VMD).
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "common/profile.hpp"
#include "md/particles.hpp"

namespace shaker::md {

/// Every particle at one stored phase of the run.
struct ParticleFrame {
  std::int64_t step = 0;   ///< stored phases since the start of the run: cycle x K + k
  std::int64_t cycle = 0;  ///< counted from 0 at the start of the run
  double time = 0.0;
  double phase = 0.0;      ///< k / K
  double plate_z = 0.0, plate_v = 0.0;
  std::vector<Vec3> r, v;  ///< x and y wrapped into [0, width) and [0, depth)
};

/// The box the frames were taken in: periodic width in x and depth in y, the ceiling above.
struct ParticleBox {
  double width = 0.0, depth = 0.0, ceiling = 0.0;
};

/// Root attribute `kind` of the H5MD particle file (a reader of run files refuses it by this).
inline constexpr const char* particle_file_kind = "shaker md particles";

/// RUN.particles.h5 and RUN.particles.xyz beside the run file `run_output`.
std::filesystem::path particle_h5_path(const std::filesystem::path& run_output);
std::filesystem::path particle_xyz_path(const std::filesystem::path& run_output);

/// Writes both particle files atomically, frames in the order given; the H5MD file's root
/// carries the run file's attributes, from `run`.
void write_particle_files(const std::filesystem::path& run_output, const std::vector<ParticleFrame>& frames,
                          const ParticleBox& box, const RunRecord& run);

/// One frame of an H5MD particle file and the file's box.
struct StoredFrame {
  ParticleFrame frame;
  std::int64_t index = 0, frames = 0;  ///< which frame (from 0), of how many
  double edges[3] = {0.0, 0.0, 0.0};   ///< /particles/all/box/edges
};

/// Frame `index` of the H5MD particle file `path` (negative: counted from the end, -1 the
/// last). InputError naming `source` (the key that gave the file) if the file is missing, not
/// HDF5, lacks the layout, has no such frame, or holds a value that is not finite.
StoredFrame read_particle_frame(const std::filesystem::path& path, std::int64_t index, const std::string& source);

}  // namespace shaker::md
