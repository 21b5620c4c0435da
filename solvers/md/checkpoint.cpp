#include "md/checkpoint.hpp"

#include <fmt/format.h>

#include <cmath>
#include <limits>
#include <utility>

#include "common/atomic_output.hpp"
#include "common/checkpoints.hpp"
#include "common/errors.hpp"
#include "common/hdf5_file.hpp"
#include "common/run_file.hpp"
#include "md/sampling.hpp"

namespace shaker::md {
namespace {

constexpr int particle_columns = 8;  // r, v, local time, last collision

std::vector<std::int64_t> widen(const auto& values) {
  return std::vector<std::int64_t>(values.begin(), values.end());
}

/// The integers of dataset `name` as T, each in [low, the largest T] (InputError otherwise: a
/// wrapped counter or index would pass every later check).
template <class T> std::vector<T> narrow(const std::vector<std::int64_t>& values, const char* name,
                                         std::int64_t low) {
  const auto high = static_cast<std::int64_t>(std::numeric_limits<T>::max());
  std::vector<T> out(values.size());
  for (std::size_t k = 0; k < values.size(); ++k) {
    if (values[k] < low || values[k] > high)
      throw InputError(fmt::format("dataset '{}' holds {} at entry {}; allowed: {} <= value <= {}",
                                   name, values[k], k, low, high));
    out[k] = static_cast<T>(values[k]);
  }
  return out;
}

/// The run's tallies: counts >= 0 and finite energies (a NaN would run on into every energy
/// column of the continued run).
void read_tally(hid_t f, Tally& t) {
  const auto counts = narrow<std::int64_t>(h5::read_integers(f, "tally_counts"), "tally_counts", 0);
  const auto energy = h5::read_doubles(f, "tally_energy");
  if (counts.size() != 7 || energy.size() != 4)
    throw InputError(fmt::format("datasets 'tally_counts' and 'tally_energy' have {} and {} entries; "
                                 "allowed: 7 and 4 (fixed length)", counts.size(), energy.size()));
  for (std::size_t k = 0; k < energy.size(); ++k)
    if (!std::isfinite(energy[k]))
      throw InputError(fmt::format("dataset 'tally_energy' holds {} at entry {} (plate work, pair "
                                   "loss, wall loss, virial); allowed: finite values", energy[k], k));
  std::uint64_t* fields[] = {&t.pair, &t.plate, &t.ceiling, &t.cell, &t.stale, &t.guard_activations, &t.grazes};
  for (std::size_t k = 0; k < 7; ++k) *fields[k] = static_cast<std::uint64_t>(counts[k]);
  t.plate_work = energy[0];
  t.pair_loss = energy[1];
  t.wall_loss = energy[2];
  t.virial = energy[3];
}

/// The sampled sums, if any (group cycle_samples, as in a run file, with the attribute
/// first_cycle).
SampledCycles read_sampled(hid_t f, const SchedulePosition& position) {
  if (!h5::exists(f, "cycle_samples")) return {};
  SampledCycles sampled;
  const h5::Handle group = h5::open_group(f, "cycle_samples");
  sampled.first_cycle = h5::read_integer_attribute(group.id(), "first_cycle");
  if (sampled.first_cycle < 0 || sampled.first_cycle > position.cycle)
    throw InputError(fmt::format("attribute 'cycle_samples/first_cycle' = {}; allowed: 0 <= value <= {} "
                                 "(schedule_cycle)", sampled.first_cycle, position.cycle));
  const auto dims = h5::shape(group.id(), "count");
  if (dims.size() != 2 || dims[1] == 0) throw InputError("dataset 'cycle_samples/count' is not a [rows x bins] matrix");
  const auto phases = static_cast<std::size_t>(position.phases);
  sampled.sums = read_samples(f, phases, dims[1], true);
  return sampled;
}

/// Kinetic plus potential energy (lab frame) of positions r and velocities v.
double system_energy(const Geometry& g, const std::vector<Vec3>& r, const std::vector<Vec3>& v) {
  double energy = 0.0;
  for (std::size_t i = 0; i < r.size(); ++i) energy += 0.5 * dot(v[i], v[i]) + g.gravity * r[i].z;
  return energy;
}

/// The energy budget is closed to 1e-9 relative from differences of the running energy totals.
/// A total beyond tally_energy_bound times the system's energy leaves fewer than 1e-9 of its
/// resolution for those differences, so the continued run could not check its budget.
inline constexpr double tally_energy_bound = 1e6;

void check_tally_scale(const Tally& t, double energy) {
  const double scale = std::max(std::fabs(energy), 1.0);
  const double values[] = {t.plate_work, t.pair_loss, t.wall_loss};
  for (std::size_t k = 0; k < 3; ++k)
    if (std::fabs(values[k]) > tally_energy_bound * scale)
      throw InputError(fmt::format(
          "dataset 'tally_energy' holds {} at entry {} (plate work, pair loss, wall loss); allowed: "
          "|value| <= {:g} x the particles' energy ({:.6g} m g sigma), beyond which the energy budget "
          "can no longer be closed to 1e-9", values[k], k, tally_energy_bound, scale));
}

}  // namespace

void write_checkpoint(const std::filesystem::path& path, const SimulationData& d, const Geometry& geometry,
                      const SchedulePosition& position, const std::string& configuration,
                      const SampledCycles& sampled) {
  write_hdf5_atomically(path, [&](const hid_t f) {
    write_checkpoint_header(f, checkpoint_kind, position, configuration);
    h5::write_attribute(f, "time", d.time);
    h5::write_attribute(f, "box_width", geometry.width);
    h5::write_attribute(f, "box_depth", geometry.depth);
    h5::write_attribute(f, "box_height", geometry.height);
    const std::size_t n = d.particles.size();
    std::vector<double> table;
    table.reserve(n * particle_columns);
    std::vector<double> event_time, cell_time;
    std::vector<std::int64_t> partner, partner_counter, kind;
    for (std::size_t i = 0; i < n; ++i) {
      const Particle& p = d.particles[i];
      for (double x : {p.r.x, p.r.y, p.r.z, p.v.x, p.v.y, p.v.z, p.t, d.last_collision[i]})
        table.push_back(x);
      event_time.push_back(d.events[i].time);
      cell_time.push_back(d.events[i].cell_time);
      partner.push_back(d.events[i].partner);
      partner_counter.push_back(d.events[i].partner_counter);
      kind.push_back(static_cast<std::int64_t>(d.events[i].kind) + 256 * d.events[i].cell_direction);
    }
    // The particle table mixes quantities: its units attribute names each column's.
    h5::write(f, "particles", table, {n, std::size_t{particle_columns}},
              "x, y, z: sigma; vx, vy, vz: sqrt(g sigma); t, last_collision: sqrt(sigma/g)");
    h5::write(f, "event_time", event_time, {n}, "sqrt(sigma/g)");
    h5::write(f, "event_cell_time", cell_time, {n}, "sqrt(sigma/g)");
    h5::write(f, "event_partner", partner, {n}, "1");
    h5::write(f, "event_partner_counter", partner_counter, {n}, "1");
    h5::write(f, "event_kind", kind, {n}, "1");
    std::vector<std::uint32_t> counters, streaks;
    for (const Particle& p : d.particles) {
      counters.push_back(p.counter);
      streaks.push_back(p.streak);
    }
    const auto count = [&](const char* name, const std::vector<std::int64_t>& values) {
      h5::write(f, name, values, {values.size()}, "1");
    };
    count("counters", widen(counters));
    count("streaks", widen(streaks));
    count("cell_head", widen(d.cell_head));
    count("cell_next", widen(d.cell_next));
    count("cell_prev", widen(d.cell_prev));
    count("cell_of", widen(d.cell_of));
    const Tally& t = d.tally;
    count("tally_counts", widen(std::vector<std::uint64_t>{t.pair, t.plate, t.ceiling, t.cell, t.stale,
                                                           t.guard_activations, t.grazes}));
    h5::write(f, "tally_energy", std::vector<double>{t.plate_work, t.pair_loss, t.wall_loss, t.virial},
              {4}, "m g sigma");
    if (sampled.sums.empty() || sampled.sums.samples(0) == 0) return;  // phase 0 is sampled first
    write_samples(f, sampled.sums, true);
    h5::write_attribute(h5::open_group(f, "cycle_samples").id(), "first_cycle", sampled.first_cycle);
  });
}

Checkpoint read_checkpoint(const std::filesystem::path& path) {
  const h5::Handle file = open_checkpoint(path, checkpoint_kind);
  const hid_t f = file.id();
  Checkpoint c;
  try {
    c.position = read_schedule_position(f);
    SimulationData& d = c.data;
    d.time = h5::read_double_attribute(f, "time");
    c.width = h5::read_double_attribute(f, "box_width");
    c.height = h5::read_double_attribute(f, "box_height");
    // Checkpoints of square boxes written before the depth was stored have none.
    c.depth = h5::has_attribute(f, "box_depth") ? h5::read_double_attribute(f, "box_depth") : c.width;
    for (const auto& [name, x] :
         {std::pair{"time", d.time}, {"box_width", c.width}, {"box_depth", c.depth}, {"box_height", c.height}})
      if (!std::isfinite(x))
        throw InputError(fmt::format("attribute '{}' = {}; allowed: a finite number", name, x));
    c.configuration = h5::read_string_attribute(f, "configuration");
    const auto dims = h5::shape(f, "particles");
    if (dims.size() != 2 || dims[1] != particle_columns)
      throw InputError(fmt::format("dataset 'particles' is not an [N x {}] matrix", particle_columns));
    const std::vector<double> table = h5::read_doubles(f, "particles");
    const std::size_t n = dims[0];
    // Every per-particle array has N entries, the tallies their fixed lengths.
    const auto require_length = [&](const char* name, std::size_t found, std::size_t expected) {
      if (found != expected)
        throw InputError(fmt::format("dataset '{}' has {} entries; allowed: {} ({})", name, found,
                                     expected, expected == n ? "one per particle" : "fixed length"));
    };
    d.particles.resize(n);
    d.last_collision.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      const double* x = &table[i * particle_columns];
      Particle& p = d.particles[i];
      p.r = {x[0], x[1], x[2]};
      p.v = {x[3], x[4], x[5]};
      p.t = x[6];
      d.last_collision[i] = x[7];
    }
    const auto event_time = h5::read_doubles(f, "event_time");
    const auto cell_time = h5::read_doubles(f, "event_cell_time");
    const auto partner = narrow<std::int32_t>(h5::read_integers(f, "event_partner"), "event_partner", -1);
    const auto partner_counter =
        narrow<std::uint32_t>(h5::read_integers(f, "event_partner_counter"), "event_partner_counter", 0);
    const auto kind = narrow<std::int16_t>(h5::read_integers(f, "event_kind"), "event_kind", 0);
    require_length("event_time", event_time.size(), n);
    require_length("event_cell_time", cell_time.size(), n);
    require_length("event_partner", partner.size(), n);
    require_length("event_partner_counter", partner_counter.size(), n);
    require_length("event_kind", kind.size(), n);
    d.events.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      d.events[i].time = event_time.at(i);
      d.events[i].partner = partner.at(i);
      d.events[i].partner_counter = partner_counter.at(i);
      d.events[i].cell_time = cell_time.at(i);
      d.events[i].kind = static_cast<EventKind>(kind.at(i) % 256);
      d.events[i].cell_direction = static_cast<std::int8_t>(kind.at(i) / 256);
    }
    const auto counters = narrow<std::uint32_t>(h5::read_integers(f, "counters"), "counters", 0);
    const auto streaks = narrow<std::uint32_t>(h5::read_integers(f, "streaks"), "streaks", 0);
    require_length("counters", counters.size(), n);
    require_length("streaks", streaks.size(), n);
    for (std::size_t i = 0; i < n; ++i) {
      d.particles[i].counter = counters[i];
      d.particles[i].streak = streaks[i];
    }
    for (auto [name, cells] : {std::pair{"cell_head", &d.cell_head}, {"cell_next", &d.cell_next},
                               {"cell_prev", &d.cell_prev}, {"cell_of", &d.cell_of}})
      *cells = narrow<std::int32_t>(h5::read_integers(f, name), name, -1);
    read_tally(f, d.tally);
    require_length("cell_next", d.cell_next.size(), n);
    require_length("cell_prev", d.cell_prev.size(), n);
    require_length("cell_of", d.cell_of.size(), n);
    c.sampled = read_sampled(f, c.position);
  } catch (const std::exception& error) {
    throw InputError(fmt::format("{} is not a valid checkpoint: {}", restart_source(path), error.what()));
  }
  return c;
}

void take_up_samples(PhaseSampler& sampler, const SampledCycles& sampled, const SchedulePosition& at,
                     const PhaseSchedule& schedule, const std::string& source) {
  const std::int64_t first = schedule.transient_cycles();
  if (at.cycle < first || (at.cycle == first && at.phase == 0)) return;  // nothing sampled yet
  const CycleSamples& saved = sampled.sums;
  const std::string sample_anew = fmt::format("or run.transient_cycles >= {} to sample only after it", at.cycle);
  if (saved.empty())
    throw InputError(fmt::format(
        "run.transient_cycles = {}, but {} (cycle {}, phase {} of {}) holds no profile sums of the "
        "sampled cycles before it (it was written in its run's transient, or by an earlier version); "
        "allowed: run.transient_cycles >= {}, sampling only after it", first, source, at.cycle, at.phase,
        at.phases, at.cycle));
  if (sampled.first_cycle != first)
    throw InputError(fmt::format("run.transient_cycles = {}, but {} holds the profile sums of the cycles "
                                 "from {}; allowed: run.transient_cycles = {}, {}", first, source,
                                 sampled.first_cycle, sampled.first_cycle, sample_anew));
  if (saved.phases() != static_cast<std::size_t>(schedule.phases()))
    throw InputError(fmt::format("run.phases_per_cycle = {}, but {} holds profile sums at {} phases; "
                                 "allowed: run.phases_per_cycle = {}, {}", schedule.phases(), source,
                                 saved.phases(), saved.phases(), sample_anew));
  const CycleSamples& mine = sampler.store();
  if (saved.bins() != mine.bins() || saved.bin_volume() != mine.bin_volume())
    throw InputError(fmt::format(
        "md.bin_height, md.ceiling, md.box_width and md.box_depth give {} sampling bins of volume {}, but {} holds "
        "profile sums in {} bins of volume {}; allowed: the checkpoint's md.bin_height, md.ceiling "
        "and md.box_width, {}", mine.bins(), mine.bin_volume(), source, saved.bins(), saved.bin_volume(),
        sample_anew));
  for (std::size_t k = 0; k < saved.phases(); ++k) {
    double cycles = 0.0;
    for (double c : saved.cycles(k)) cycles += c;
    const std::int64_t expected = at.cycle - first + (static_cast<std::int64_t>(k) < at.phase ? 1 : 0);
    if (cycles != static_cast<double>(expected))
      throw InputError(fmt::format("{} is not a valid checkpoint: dataset 'cycle_samples/cycles' holds {} "
                                   "sampled cycles at phase {}; allowed: {} (cycles {} to {}, phase {})", source,
                                   cycles, k, expected, first, at.cycle, at.phase));
  }
  std::vector<double> first_times;
  for (std::int64_t k = 0; k < schedule.phases(); ++k) first_times.push_back(schedule.target(first, k));
  sampler.resume(saved, first_times);
}

void validate_state(const Geometry& g, const SimulationData& d, double tolerance) {
  const std::size_t n = d.particles.size();
  std::vector<Vec3> r(n), v(n);
  for (std::size_t i = 0; i < n; ++i) {
    if (!(d.particles[i].t <= d.time))
      throw InputError(fmt::format("checkpoint particle {}: local time {} is after the checkpoint "
                                   "time {}", i, d.particles[i].t, d.time));
    state_at(d.particles[i], d.time, g.gravity, r[i], v[i]);
    const double x = r[i].x, y = r[i].y, z = r[i].z;
    const bool inside_xy = x >= -tolerance && x <= g.width + tolerance && y >= -tolerance &&
                           y <= g.depth + tolerance;
    const double z_lo = g.periodic_z ? -tolerance : g.plate.position(d.time) + 0.5 - tolerance;
    const double z_hi = g.periodic_z ? g.height + tolerance : g.height - 0.5 + tolerance;
    const bool finite = std::isfinite(x) && std::isfinite(y) && std::isfinite(z);
    if (!finite || !inside_xy || z < z_lo || z > z_hi || !std::isfinite(dot(v[i], v[i])))
      throw InputError(fmt::format(
          "particle {} at ({}, {}, {}) is outside the box: allowed 0 <= x <= {}, 0 <= y <= {} "
          "and {} <= z <= {} at t = {}", i, x, y, z, g.width, g.depth, z_lo + tolerance, z_hi - tolerance,
          d.time));
  }
  check_tally_scale(d.tally, system_energy(g, r, v));
  Geometry cells_geometry = g;
  CellList cells;
  cells.build(cells_geometry, n);
  for (std::size_t i = 0; i < n; ++i) cells.insert(static_cast<std::int32_t>(i), cells.cell_of(r[i]));
  const double limit = (1.0 - tolerance) * (1.0 - tolerance);
  for (std::size_t i = 0; i < n; ++i) {
    cells.for_each_neighbor(cells.cell(static_cast<std::int32_t>(i)), [&](std::int32_t j, const Vec3& shift) {
      if (j <= static_cast<std::int32_t>(i)) return;
      const Vec3 dr = r[i] - r[static_cast<std::size_t>(j)] - shift;
      if (dot(dr, dr) < limit)
        throw InputError(fmt::format(
            "particles {} and {} overlap: centre distance {:.12g}, allowed at least "
            "1 - {:g} (one diameter)", i, j, std::sqrt(dot(dr, dr)), tolerance));
    });
  }
}

}  // namespace shaker::md
