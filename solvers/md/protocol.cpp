#include "md/protocol.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <chrono>
#include <cmath>

#include "common/errors.hpp"
#include "md/sampling.hpp"

namespace shaker::md {

std::string crossing_column(double height) { return fmt::format("crossings_z{:g}", height); }

MdSettings MdSettings::from(const config::Config& c) {
  MdSettings s;
  s.ceiling = c.real("md.ceiling");
  s.bin_height = c.real("md.bin_height");
  s.initial_state = c.text("md.initial_state");
  s.gas_volume_fraction = c.real("md.gas_volume_fraction");
  s.gas_temperature = c.real("md.gas_temperature");
  s.checkpoint = c.text("md.checkpoint");
  s.checkpoint_output = c.text("md.checkpoint_output");
  s.tc_guard = c.text("md.collapse_guard") == "tc";
  s.tc = c.real("md.tc");
  s.queue = c.text("md.event_queue") == "calendar" ? QueueKind::calendar : QueueKind::heap;
  s.crossing_heights = c.real_list("md.crossing_heights");
  for (std::size_t k = 0; k < s.crossing_heights.size(); ++k)
    for (std::size_t m = 0; m < k; ++m)
      if (crossing_column(s.crossing_heights[k]) == crossing_column(s.crossing_heights[m]))
        throw InputError(fmt::format("md.crossing_heights = [{}]: the heights {} and {} give the "
                                     "same column name {}; allowed: distinct heights > 0",
                                     fmt::join(s.crossing_heights, ", "), s.crossing_heights[m],
                                     s.crossing_heights[k], crossing_column(s.crossing_heights[k])));
  return s;
}

namespace {

/// Time-series columns, one row per sampling instant.
struct SeriesRows {
  std::vector<std::string> names = {
      "t", "phase", "plate_z", "com_z", "kinetic", "potential", "plate_work",
      "collisional_loss", "energy_closure", "pair_collisions", "plate_collisions",
      "ceiling_collisions", "cell_crossings", "guard_activations", "overlaps", "near_plate",
      "collisions", "queue_consistent"};
  std::vector<std::vector<double>> columns;
  explicit SeriesRows(const std::vector<double>& crossing_heights) {
    for (double h : crossing_heights) names.push_back(crossing_column(h));
    columns.resize(names.size());
  }
  void add(std::initializer_list<double> row, const std::vector<std::uint64_t>& crossings) {
    std::size_t k = 0;
    for (double x : row) columns[k++].push_back(x);
    for (std::uint64_t c : crossings) columns[k++].push_back(static_cast<double>(c));
  }
  TimeSeries finish() {
    TimeSeries s;
    for (std::size_t k = 0; k < columns.size(); ++k) s.add(names[k], std::move(columns[k]));
    return s;
  }
};

}  // namespace

RunOutcome run_protocol(Simulation& sim, const CaseParameters& parameters,
                        const MdSettings& settings, const Progress& progress) {
  const ShakerKinematics& shaker = parameters.shaker;
  const RunProtocol& protocol = parameters.run;
  const bool single_shock = protocol.kind == RunProtocol::Kind::single_shock;
  const long phases = static_cast<long>(protocol.phases_per_cycle);
  const long transient = static_cast<long>(protocol.transient_cycles);
  const long sampled = single_shock ? 1 : static_cast<long>(protocol.sampled_cycles);
  const long cycles = transient + sampled;
  const double f = shaker.f;
  const double first_cycle = std::ceil(sim.time() * f - 1e-9);
  const double switch_time = (first_cycle + static_cast<double>(transient) + protocol.switch_phase) / f;
  bool switched = !single_shock;

  const auto n = static_cast<double>(sim.size());
  const double energy0 = sim.kinetic_energy(sim.time()) + sim.potential_energy(sim.time());
  const Tally tally0 = sim.tally();
  RunOutcome out;
  auto budget_now = [&](double energy) {
    const Tally& tally = sim.tally();
    EnergyBudget b;
    b.plate_work = tally.plate_work - tally0.plate_work;
    b.collisional_loss = tally.pair_loss + tally.wall_loss - tally0.pair_loss - tally0.wall_loss;
    b.energy_change = energy - energy0;
    const double scale = std::max({std::fabs(b.plate_work), std::fabs(b.collisional_loss), std::fabs(energy), 1e-300});
    b.relative_closure = std::fabs(b.energy_change + b.collisional_loss - b.plate_work) / scale;
    return b;
  };

  PhaseSampler sampler(static_cast<int>(phases), settings.bin_height, settings.ceiling,
                       sim.geometry().width);
  SeriesRows rows(settings.crossing_heights);
  sim.count_crossings(settings.crossing_heights);
  std::vector<Vec3> r, v;
  auto record = [&](double t) {
    sim.positions_at(t, r, v);
    double com = 0.0, near_plate = 0.0, kinetic = 0.0;
    const double plate_z = shaker.position(t);
    for (std::size_t i = 0; i < r.size(); ++i) {
      com += r[i].z;
      kinetic += 0.5 * dot(v[i], v[i]);
      near_plate += r[i].z - 0.5 - plate_z < 0.5 ? 1.0 : 0.0;  // within half a diameter
    }
    const double potential = sim.geometry().gravity * com;
    const EnergyBudget b = budget_now(kinetic + potential);
    const Tally& tally = sim.tally();
    rows.add({t, shaker.phase(t), plate_z, com / n, kinetic, potential, b.plate_work, b.collisional_loss, b.relative_closure,
              static_cast<double>(tally.pair), static_cast<double>(tally.plate),
              static_cast<double>(tally.ceiling), static_cast<double>(tally.cell),
              static_cast<double>(tally.guard_activations),
              static_cast<double>(sim.count_overlaps(r, 1e-9)), near_plate,
              static_cast<double>(tally.pair - tally0.pair),
              sim.queue_consistent() ? 1.0 : 0.0},
             sim.crossings_at(t));
  };

  const auto start = std::chrono::steady_clock::now();
  for (long m = 0; m < cycles; ++m) {
    for (long k = 0; k < phases; ++k) {
      const double t = (first_cycle + static_cast<double>(m) + static_cast<double>(k) / static_cast<double>(phases)) / f;
      if (!switched && switch_time <= t) {
        sim.advance_to(switch_time);
        sim.set_restitution(protocol.after_switch);
        switched = true;
      }
      sim.advance_to(t);
      record(t);
      if (m >= transient) sampler.add(static_cast<int>(k), t, r, v);
    }
    if (progress) {
      const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      progress(m + 1, cycles, static_cast<double>(sim.tally().collisions() - tally0.collisions()) / seconds);
    }
  }
  const double end = (first_cycle + static_cast<double>(cycles)) / f;
  sim.advance_to(end);
  record(end);
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  out.profiles = sampler.profiles(shaker);
  out.samples = sampler.samples();
  out.series = rows.finish();
  out.budget = budget_now(sim.kinetic_energy(end) + sim.potential_energy(end));
  out.overlaps = sim.count_overlaps(end, 1e-9);
  out.queue_consistent = sim.queue_consistent();
  const Tally& tally = sim.tally();
  out.collisions = tally.collisions() - tally0.collisions();
  out.events = out.collisions + (tally.cell - tally0.cell) + (tally.stale - tally0.stale) +
               (tally.grazes - tally0.grazes);
  return out;
}

}  // namespace shaker::md
