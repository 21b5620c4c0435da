#include "md/particle_file.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <stdexcept>

#include "common/atomic_output.hpp"
#include "common/errors.hpp"
#include "common/hdf5_file.hpp"
#include "common/run_file.hpp"
#include "common/version.hpp"

namespace shaker::md {
namespace {

constexpr const char* length_units = "sigma";
constexpr const char* time_units = "sqrt(sigma/g)";
constexpr const char* velocity_units = "sqrt(g sigma)";

// Where the H5MD file keeps what a run starts from.
constexpr const char* position_group = "particles/all/position";
constexpr const char* velocity_group = "particles/all/velocity";
constexpr const char* edges_dataset = "particles/all/box/edges";

/// H5MD's author: the user who ran the program.
std::string author_name() {
  for (const char* variable : {"USER", "LOGNAME"})
    if (const char* name = std::getenv(variable); name != nullptr && *name != '\0') return name;
  return "unknown";
}

/// An H5MD time-dependent element `name`: step and time [frames], value [frames x shape].
template <class T>
void write_element(hid_t parent, const std::string& name, const std::vector<ParticleFrame>& frames,
                   const std::vector<T>& values, std::vector<std::size_t> shape, const std::string& units) {
  const h5::Handle group = h5::create_group(parent, name);
  std::vector<std::int64_t> steps;
  std::vector<double> times;
  for (const ParticleFrame& f : frames) {
    steps.push_back(f.step);
    times.push_back(f.time);
  }
  h5::write_extendable(group.id(), "step", steps, {frames.size()}, "1");
  h5::write_extendable(group.id(), "time", times, {frames.size()}, time_units);
  shape.insert(shape.begin(), frames.size());
  h5::write_extendable(group.id(), "value", values, shape, units);
}

/// One number per frame.
template <class T, class Of>
std::vector<T> per_frame(const std::vector<ParticleFrame>& frames, Of of) {
  std::vector<T> values;
  for (const ParticleFrame& f : frames) values.push_back(of(f));
  return values;
}

/// The vectors of every frame, [frames x particles x 3].
std::vector<double> flattened(const std::vector<ParticleFrame>& frames, std::vector<Vec3> ParticleFrame::*of) {
  std::vector<double> values;
  for (const ParticleFrame& f : frames)
    for (const Vec3& x : f.*of) values.insert(values.end(), {x.x, x.y, x.z});
  return values;
}

void write_h5md(hid_t root, const std::vector<ParticleFrame>& frames, const ParticleBox& box, const RunRecord& run) {
  write_run_attributes(root, run);
  h5::write_attribute(root, file_kind_attribute, std::string(particle_file_kind));
  {
    const h5::Handle h5md = h5::create_group(root, "h5md");
    h5::write_attribute(h5md.id(), "version", std::vector<std::int64_t>{1, 1});
    const h5::Handle author = h5::create_group(h5md.id(), "author");
    h5::write_attribute(author.id(), "name", author_name());
    const h5::Handle creator = h5::create_group(h5md.id(), "creator");
    h5::write_attribute(creator.id(), "name", std::string("granular-shaker"));
    h5::write_attribute(creator.id(), "version", std::string(program_version()));
  }
  const std::size_t n = frames.front().r.size();
  {
    const h5::Handle particles = h5::create_group(root, "particles");
    const h5::Handle all = h5::create_group(particles.id(), "all");
    const h5::Handle box_group = h5::create_group(all.id(), "box");
    h5::write_attribute(box_group.id(), "dimension", std::int64_t{3});
    h5::write_attribute(box_group.id(), "boundary", std::vector<std::string>{"periodic", "periodic", "none"});
    h5::write(box_group.id(), "edges", std::vector<double>{box.width, box.depth, box.ceiling}, {3}, length_units);
    write_element(all.id(), "position", frames, flattened(frames, &ParticleFrame::r), {n, 3}, length_units);
    write_element(all.id(), "velocity", frames, flattened(frames, &ParticleFrame::v), {n, 3}, velocity_units);
  }
  const h5::Handle observables = h5::create_group(root, "observables");
  const auto scalar = [&](const char* name, auto of, const char* units) {
    write_element(observables.id(), name, frames, per_frame<decltype(of(frames.front()))>(frames, of), {}, units);
  };
  scalar("plate_position", [](const ParticleFrame& f) { return f.plate_z; }, length_units);
  scalar("plate_velocity", [](const ParticleFrame& f) { return f.plate_v; }, velocity_units);
  scalar("phase", [](const ParticleFrame& f) { return f.phase; }, "1");
  scalar("cycle", [](const ParticleFrame& f) { return f.cycle; }, "1");
}

/// Extended XYZ, one frame after the other; numbers in shortest round-trip form, so that a
/// reader gets the doubles of the H5MD file.
std::string xyz_text(const std::vector<ParticleFrame>& frames, const ParticleBox& box) {
  std::string text;
  for (const ParticleFrame& f : frames) {
    text += fmt::format("{}\nLattice=\"{} 0 0 0 {} 0 0 0 {}\" Properties=species:S:1:pos:R:3:vel:R:3 "
                        "pbc=\"T T F\" Time={} step={} cycle={} phase={} plate_z={} plate_v={} "
                        "units=\"length {}, time {}, velocity {}\"\n",
                        f.r.size(), box.width, box.depth, box.ceiling, f.time, f.step, f.cycle, f.phase,
                        f.plate_z, f.plate_v, length_units, time_units, velocity_units);
    for (std::size_t i = 0; i < f.r.size(); ++i)
      text += fmt::format("X {} {} {} {} {} {}\n", f.r[i].x, f.r[i].y, f.r[i].z, f.v[i].x, f.v[i].y, f.v[i].z);
  }
  return text;
}

/// The shape of `name`; InputError unless it is `wanted` (a 0 there: any size >= 1), which
/// `meaning` describes.
std::vector<std::size_t> checked_shape(hid_t file, const std::string& name, const std::vector<std::size_t>& wanted,
                                       const std::string& meaning) {
  const std::vector<std::size_t> dims = h5::shape(file, name);
  bool ok = dims.size() == wanted.size();
  for (std::size_t k = 0; ok && k < dims.size(); ++k) ok = wanted[k] == 0 ? dims[k] > 0 : dims[k] == wanted[k];
  if (!ok)
    throw InputError(fmt::format("dataset '{}' has shape [{}]; allowed: {}", name, fmt::join(dims, ", "), meaning));
  return dims;
}

bool finite(const double* x, std::size_t count) {
  return std::all_of(x, x + count, [](double y) { return std::isfinite(y); });
}

std::string triple(const double* x) { return fmt::format("({}, {}, {})", x[0], x[1], x[2]); }

}  // namespace

std::filesystem::path particle_h5_path(const std::filesystem::path& run_output) {
  return derived_name(run_output, ".particles.h5");
}
std::filesystem::path particle_xyz_path(const std::filesystem::path& run_output) {
  return derived_name(run_output, ".particles.xyz");
}

void write_particle_files(const std::filesystem::path& run_output, const std::vector<ParticleFrame>& frames,
                          const ParticleBox& box, const RunRecord& run) {
  if (frames.empty()) throw std::logic_error("write_particle_files: no frame");
  for (const ParticleFrame& f : frames)
    if (f.r.size() != frames.front().r.size() || f.v.size() != f.r.size())
      throw std::logic_error("write_particle_files: frames differ in their number of particles");
  write_hdf5_atomically(particle_h5_path(run_output), [&](hid_t root) { write_h5md(root, frames, box, run); });
  write_text_atomically(particle_xyz_path(run_output), xyz_text(frames, box));
}

StoredFrame read_particle_frame(const std::filesystem::path& path, std::int64_t index, const std::string& source) {
  try {
    const h5::Handle file = h5::open_file(path);
    const std::string position = std::string(position_group) + "/value";
    const std::string velocity = std::string(velocity_group) + "/value";
    const std::string time = std::string(position_group) + "/time";
    const std::string step = std::string(position_group) + "/step";
    const std::vector<std::size_t> dims =
        checked_shape(file.id(), position, {0, 0, 3}, "[frames x particles x 3], frames and particles >= 1");
    const std::string per_frame = fmt::format("[{}], one per frame of {}", dims[0], position);
    checked_shape(file.id(), velocity, {dims[0], dims[1], 3}, fmt::format("[{} x {} x 3], as {}", dims[0], dims[1], position));
    checked_shape(file.id(), time, {dims[0]}, per_frame);
    checked_shape(file.id(), step, {dims[0]}, per_frame);
    checked_shape(file.id(), edges_dataset, {3}, "[3], the box's edges in x, y and z");
    StoredFrame stored;
    stored.frames = static_cast<std::int64_t>(dims[0]);
    if (index < -stored.frames || index >= stored.frames)
      throw InputError(fmt::format("it holds {} frame(s), and md.initial_frame = {}; allowed: md.initial_frame "
                                   "from {} to {} (negative counts from the end)", stored.frames, index,
                                   -stored.frames, stored.frames - 1));
    stored.index = index < 0 ? stored.frames + index : index;
    const auto row = static_cast<std::size_t>(stored.index);
    const std::vector<double> edges = h5::read_doubles(file.id(), edges_dataset);
    std::copy(edges.begin(), edges.end(), stored.edges);
    ParticleFrame& f = stored.frame;
    f.time = h5::read_row(file.id(), time, row).front();
    if (!(std::isfinite(f.time) && f.time >= 0.0))
      throw InputError(fmt::format("frame {} has time {} ({}); allowed: a finite time >= 0", stored.index,
                                   f.time, time));
    if (!finite(edges.data(), 3))
      throw InputError(fmt::format("the box edges {} ({}) are not finite", triple(edges.data()), edges_dataset));
    const std::vector<double> r = h5::read_row(file.id(), position, row), v = h5::read_row(file.id(), velocity, row);
    for (std::size_t i = 0; i < dims[1]; ++i) {
      const double *x = &r[3 * i], *u = &v[3 * i];
      if (!finite(x, 3) || !finite(u, 3))
        throw InputError(fmt::format("particle {} of frame {} is at {} with velocity {}; allowed: finite values",
                                     i, stored.index, triple(x), triple(u)));
      f.r.push_back({x[0], x[1], x[2]});
      f.v.push_back({u[0], u[1], u[2]});
    }
    return stored;
  } catch (const InputError& error) {
    throw InputError(fmt::format("{}: {}", source, error.what()));
  } catch (const std::runtime_error& error) {
    throw InputError(fmt::format("{} is unreadable: {}", source, error.what()));
  }
}

}  // namespace shaker::md
