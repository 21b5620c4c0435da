// Continuing the engine from saved state (a checkpoint): what a checkpoint must hold for the
// run to go on exactly as the one that wrote it, checked before anything is rebuilt.
#include "md/simulation.hpp"

#include <fmt/format.h>

#include "common/errors.hpp"

namespace shaker::md {

namespace {

/// What is wrong with the pending events of a checkpoint (empty if nothing).
std::string event_inconsistency(const SimulationData& d) {
  const auto n = static_cast<std::int32_t>(d.particles.size());
  if (d.events.size() != d.particles.size()) return fmt::format("{} events for {} particles", d.events.size(), n);
  for (std::int32_t i = 0; i < n; ++i) {
    const Event& e = d.events[static_cast<std::size_t>(i)];
    const auto kind = static_cast<int>(e.kind);
    if (kind > static_cast<int>(EventKind::ceiling))
      return fmt::format("particle {}: event kind {}; allowed 0 to 2 (pair, plate, ceiling)", i, kind);
    if (e.cell_direction < 0 || e.cell_direction > 5)
      return fmt::format("particle {}: cell crossing direction {}; allowed 0 to 5", i, e.cell_direction);
    if (e.partner < -1 || e.partner >= n || e.partner == i)
      return fmt::format("particle {}: partner {}; allowed -1 (none) or 0 to {} other than {}", i, e.partner, n - 1, i);
    if (e.kind == EventKind::pair && e.time < never && e.partner < 0)
      return fmt::format("particle {}: a pair collision at t = {} without a partner", i, e.time);
    if (!(e.time >= d.time) || !(e.cell_time >= d.time))
      return fmt::format("particle {}: event at t = {}, cell crossing at t = {}; allowed: not before the "
                         "checkpoint time {}", i, e.time, e.cell_time, d.time);
  }
  return {};
}

}  // namespace

Simulation::Simulation(const Geometry& geometry, const CollisionRules& rules, SimulationData saved,
                       QueueKind queue)
    : geometry_(geometry), rules_(rules), data_(std::move(saved)),
      use_calendar_(queue == QueueKind::calendar) {
  const std::size_t n = data_.particles.size();
  data_.last_collision.resize(n, no_collision_yet);
  cells_.build(geometry_, n);
  if (data_.cell_head.size() != cells_.head_.size())
    throw InputError(fmt::format("checkpoint cell grid has {} cells, this geometry needs {} (written "
                                 "by another version of the solver)", data_.cell_head.size(), cells_.head_.size()));
  cells_.head_ = std::move(data_.cell_head);
  cells_.next_ = std::move(data_.cell_next);
  cells_.prev_ = std::move(data_.cell_prev);
  cells_.cell_ = std::move(data_.cell_of);
  data_.cell_head.clear();
  data_.cell_next.clear();
  data_.cell_prev.clear();
  data_.cell_of.clear();
  if (const std::string problem = cells_.inconsistency(data_.particles, 1e-6); !problem.empty())
    throw InputError("checkpoint cell lists: " + problem + " (a damaged or edited checkpoint)");
  if (const std::string problem = event_inconsistency(data_); !problem.empty())
    throw InputError("checkpoint events: " + problem + " (a damaged or edited checkpoint)");
  reset_queue(n);
  for (std::size_t i = 0; i < n; ++i)
    schedule(static_cast<std::int32_t>(i), data_.events[i].next());
}

SimulationData Simulation::save() const {
  SimulationData copy = data_;
  copy.cell_head = cells_.head_;
  copy.cell_next = cells_.next_;
  copy.cell_prev = cells_.prev_;
  copy.cell_of = cells_.cell_;
  return copy;
}

}  // namespace shaker::md
