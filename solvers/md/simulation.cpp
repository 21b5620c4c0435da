// The engine's hot path: one event after another (step), the predictions that follow it and
// the prefetching that hides their memory latency. Restoring from a checkpoint (restore.cpp),
// keeping particles in cell order (cell_order.cpp) and the run's checks (diagnostics.cpp) live
// apart, so that this file holds only what runs between two events.
#include "md/simulation.hpp"

#include <fmt/format.h>

#include <cmath>
#include <cstdlib>

#include "common/errors.hpp"
#include "md/prefetch.hpp"

namespace shaker::md {

Simulation::Simulation(const Geometry& geometry, const CollisionRules& rules, const State& initial,
                       QueueKind queue)
    : geometry_(geometry), rules_(rules), use_calendar_(queue == QueueKind::calendar) {
  const std::size_t n = initial.particles.size();
  data_.time = initial.time;
  data_.particles = initial.particles;
  data_.events.assign(n, Event{});
  for (Particle& p : data_.particles) p.counter = p.streak = 0;
  data_.last_collision = initial.last_collision;
  data_.last_collision.resize(n, no_collision_yet);
  cells_.build(geometry_, n);
  for (std::size_t i = 0; i < n; ++i) {
    Particle& p = data_.particles[i];
    advance(p, data_.time, geometry_.gravity);  // predictions assume p.t == now
    cells_.insert(static_cast<std::int32_t>(i), cells_.cell_of(p.r));
  }
  reset_queue(n);
  for (std::size_t i = 0; i < n; ++i) predict(static_cast<std::int32_t>(i));
}

void Simulation::advance_to(double t) {
  // Collapse the per-particle detector cannot see (events that are not collisions, at e = 0
  // pairs that touch without approaching): the clock stops while events go on, and the run
  // would never reach t nor a stored phase where a stop signal is acted on.
  const std::uint64_t limit = stalled_events_per_particle * data_.particles.size() + stalled_events_floor;
  std::uint64_t stalled = 0;
  double since = data_.time;
  while ((use_calendar_ ? calendar_.top_time() : heap_.top_time()) <= t) {
    step();
    if (data_.time - since >= collapse_interval) {
      since = data_.time;
      stalled = 0;
    } else if (++stalled > limit) {
      throw CollapseError(fmt::format(
          "inelastic collapse at t = {:.9g}: {} events without the time advancing by {:g} (the "
          "particles in contact no longer separate); set md.collapse_guard = \"tc\" or use a larger "
          "e (material.e, run.switch_e)", data_.time, stalled, collapse_interval));
    }
  }
  data_.time = t;
}

void Simulation::prefetch_stage1(std::int32_t a) const {
  const auto k = static_cast<std::size_t>(a);
  prefetch(&data_.events[k]);
  prefetch(&data_.particles[k]);
  prefetch(&cells_.cell_[k]);
}

void Simulation::prefetch_stage2(std::int32_t a) const {
  const Event& e = data_.events[static_cast<std::size_t>(a)];
  const int c = cells_.cell(a);
  if (e.cell_time < e.time) {
    cells_.prefetch_block(cells_.neighbor_cell(c, e.cell_direction));
    cells_.prefetch_links(a);  // the crossing unlinks a from its cell
    return;
  }
  cells_.prefetch_block(c);
  if (e.kind == EventKind::pair && e.partner >= 0) {
    const auto b = static_cast<std::size_t>(e.partner);
    prefetch(&data_.particles[b]);
    prefetch(&data_.events[b]);
    prefetch(&cells_.cell_[b]);
    if (use_calendar_) calendar_.prefetch(e.partner);
    else heap_.prefetch(e.partner);
  }
}

void Simulation::prefetch_stage3(std::int32_t a) const {
  const Event& e = data_.events[static_cast<std::size_t>(a)];
  const int c = cells_.cell(a);
  if (e.cell_time < e.time) {
    prefetch_members(cells_.neighbor_cell(c, e.cell_direction), e.cell_direction / 2,
                     (e.cell_direction & 1) ? 1 : -1);
    return;
  }
  prefetch_members(c);
  if (e.kind == EventKind::pair && e.partner >= 0) cells_.prefetch_block(cells_.cell(e.partner));
}

void Simulation::prefetch_members(int c, int axis, int step) const {
  const Particle* particles = data_.particles.data();
  auto touch = [&](int cell, const Vec3&) {
    // Without a branch (whether a cell is empty is a coin toss): an empty cell prefetches
    // particle 0's lines instead, which costs nothing.
    const std::int32_t h = cells_.head_[static_cast<std::size_t>(cell)];
    const auto k = static_cast<std::size_t>(h < 0 ? 0 : h);
    prefetch(&cells_.next_[k]);
    prefetch(particles + k);
  };
  if (axis < 0) cells_.for_each_neighbor_cell(c, touch);
  else cells_.for_each_cell_in_new_face(c, axis, step, touch);
}

void Simulation::prefetch_ahead(const Event& event) {
  // Events k + 1 and k + 2 are (most likely) the next two in the queue, the partner's entry
  // aside (it usually holds this same collision and is about to move); the calendar's cursor
  // meets later ones a few events ahead.
  const std::int32_t partner = event.cell_time < event.time || event.kind != EventKind::pair ? -1 : event.partner;
  std::int32_t ahead[3];
  if (use_calendar_) {
    std::int32_t later[2];
    const int reached = calendar_.walk_ahead(later);
    for (int k = 0; k < reached; ++k) prefetch_stage1(later[k]);
    calendar_.peek_after_top(partner, ahead);
    // Each stage reads only what an earlier step prefetched (if the guesses hold).
    if (ahead[2] >= 0) prefetch_stage1(ahead[2]);
    if (ahead[1] >= 0) prefetch_stage2(ahead[1]);
    if (ahead[0] >= 0 && lookahead_members_) prefetch_stage3(ahead[0]);
  } else {
    heap_.peek_after_top(partner, ahead);
    if (ahead[1] >= 0) prefetch_stage1(ahead[1]);
    if (ahead[0] >= 0) prefetch_stage2(ahead[0]);
  }
}

bool Simulation::pair_event(std::int32_t i, const Event& event, double before_i) {
  const double now = data_.time;
  Tally& tally = data_.tally;
  const std::int32_t j = event.partner;
  Particle& p = data_.particles[i];
  Particle& q = data_.particles[j];
  if (q.counter != event.partner_counter) {
    ++tally.stale;
    return false;
  }
  if (lookahead_members_) prefetch_members(cells_.cell(j));
  const double before_j = q.t;
  update(j, now);
  Vec3 r = p.r - q.r;  // minimum image: at contact |r| = 1 < width / 2
  r.x -= geometry_.width * std::round(r.x / geometry_.width);
  r.y -= geometry_.depth * std::round(r.y / geometry_.depth);
  if (geometry_.periodic_z) r.z -= geometry_.height * std::round(r.z / geometry_.height);
  const bool tc = rules_.tc_guard;
  const PairCollision c = collide_pair(p, q, r, now, tc ? last_collision(i, before_i, rules_.tc) : no_collision_yet,
                                       tc ? last_collision(j, before_j, rules_.tc) : no_collision_yet, rules_);
  ++tally.pair;
  if (c.happened) {
    tally.pair_loss += c.loss;
    tally.virial += c.virial;
    tally.guard_activations += c.elastic_by_guard ? 1 : 0;
    note_collision(i, j, before_i);
    note_collision(j, i, before_j);
  }
  // i first: its cells were prefetched longer ago (the order does not change the result:
  // each prediction writes only its own event, and the queue's order is total).
  predict(i);
  predict(j);
  // Deterministic in the run's own history (a restart sorts at the same collisions).
  if (data_.tally.pair % (sort_interval * data_.particles.size()) == 0) sort_by_cell();
  return true;
}

void Simulation::wall_event(std::int32_t i, EventKind kind, double before_i) {
  const double now = data_.time;
  Tally& tally = data_.tally;
  Particle& p = data_.particles[i];
  const bool plate = kind == EventKind::plate;
  const double last = rules_.tc_guard ? last_collision(i, before_i, rules_.tc) : no_collision_yet;
  const WallCollision c = plate ? collide_wall(p, geometry_.plate.velocity(now), 1.0, now, last, rules_)
                                : collide_wall(p, 0.0, -1.0, now, last, rules_);
  ++(plate ? tally.plate : tally.ceiling);
  if (c.changed) {
    tally.plate_work += c.work;
    tally.wall_loss += c.loss;
    tally.guard_activations += c.elastic_by_guard ? 1 : 0;
    note_collision(i, -1, before_i);
  } else {
    ++tally.grazes;
  }
}

void Simulation::step() {
  const std::int32_t i = use_calendar_ ? calendar_.top() : heap_.top();
  const Event event = data_.events[i];
  if (lookahead_) prefetch_ahead(event);
  const bool crossing = event.cell_time < event.time;
  data_.time = crossing ? event.cell_time : event.time;
  const double before_i = data_.particles[i].t;
  update(i, data_.time);
  if (crossing) {
    ++data_.tally.cell;
    cross_cell(i, event.cell_direction);
    predict_after_crossing(i, event.cell_direction);
    return;
  }
  if (event.kind == EventKind::pair) {
    if (pair_event(i, event, before_i)) return;  // both predicted
  } else if (event.kind != EventKind::cell) {
    wall_event(i, event.kind, before_i);
  }
  predict(i);
}

void Simulation::update(std::int32_t i, double now) {
  Particle& p = data_.particles[i];
  height_counts_.count_flight(i, p, now);
  advance(p, now, geometry_.gravity);
}

void Simulation::note_collision(std::int32_t i, std::int32_t partner, double before) {
  Particle& p = data_.particles[i];
  ++p.counter;
  const double now = data_.time;
  if (!rules_.tc_guard) {
    if (now - last_collision(i, before, collapse_interval) < collapse_interval) {
      if (++p.streak >= collapse_streak) {
        const std::string with = partner >= 0 ? fmt::format("particle {}", partner) : "a wall";
        throw CollapseError(fmt::format(
            "inelastic collapse at t = {:.9g}: particle {} (with {}) has had {} collisions in a "
            "row less than {:g} apart (collision rate above {:.3g} per unit time); set "
            "md.collapse_guard = \"tc\" or use a larger e",
            now, i, with, p.streak, collapse_interval, 1.0 / collapse_interval));
      }
    } else {
      p.streak = 0;
    }
  }
  data_.last_collision[static_cast<std::size_t>(i)] = now;
}

double Simulation::cell_crossing_delay(const Particle& p, int c, std::int32_t& direction) const {
  double best = never;
  auto linear = [&](double u, double vu, double lo, double hi, std::int32_t axis) {
    if (vu > 0.0) {
      const double dt = std::max(hi - u, 0.0) / vu;
      if (dt < best) { best = dt; direction = 2 * axis + 1; }
    } else if (vu < 0.0) {
      const double dt = std::max(u - lo, 0.0) / -vu;
      if (dt < best) { best = dt; direction = 2 * axis; }
    }
  };
  const double x0 = cells_.ix(c) * cells_.edge_x(), y0 = cells_.iy(c) * cells_.edge_y();
  const double z0 = cells_.iz(c) * cells_.edge_z();
  linear(p.r.x, p.v.x, x0, x0 + cells_.edge_x(), 0);
  linear(p.r.y, p.v.y, y0, y0 + cells_.edge_y(), 1);
  if (geometry_.periodic_z && geometry_.gravity == 0.0) {
    linear(p.r.z, p.v.z, z0, z0 + cells_.edge_z(), 2);
    return best;
  }
  // Vertical: the walls bound the outermost rows, and gravity bends the path back down.
  const int iz = cells_.iz(c);
  const bool wrap = geometry_.periodic_z;
  const double up = (iz + 1 < cells_.nz() || wrap) ? rise_delay(p.r.z, p.v.z, geometry_.gravity, z0 + cells_.edge_z()) : never;
  const double down = up == never && (iz > 0 || wrap) ? fall_delay(p.r.z, p.v.z, geometry_.gravity, z0) : never;
  if (up < best) { best = up; direction = 5; }
  if (down < best) { best = down; direction = 4; }
  return best;
}

void Simulation::cross_cell(std::int32_t i, std::int32_t direction) {
  Particle& p = data_.particles[i];
  const int c = cells_.cell(i);
  int x = cells_.ix(c), y = cells_.iy(c), z = cells_.iz(c);
  const int step = (direction & 1) ? 1 : -1;
  auto move = [&](int& index, int count, double& coordinate, double length) {
    index += step;
    if (index < 0) { index += count; coordinate += length; }
    else if (index >= count) { index -= count; coordinate -= length; }
  };
  switch (direction / 2) {
    case 0: move(x, cells_.nx(), p.r.x, geometry_.width); break;
    case 1: move(y, cells_.ny(), p.r.y, geometry_.depth); break;
    default: move(z, cells_.nz(), p.r.z, geometry_.height); break;
  }
  cells_.remove(i);
  cells_.insert(i, cells_.index(x, y, z));
}

namespace {

/// Appends the particles of one cell (except `self`) to the batch, prefetching their states;
/// calls flush() whenever the batch is full. A cell of the gas holds 0.6 particles on average,
/// so whether it is empty, or holds a second one, is a coin toss for the branch predictor: the
/// first two are taken without branches (a slot is written and kept only if the id is a
/// particle), only a third and later ones loop.
template <class Flush>
[[gnu::always_inline]] inline void collect_cell(PairBatch& batch, const CellList& cells, const Particle* particles, int cell,
                  const Vec3& shift, std::int32_t self, Flush&& flush) {
  if (batch.count > PairBatch::capacity - 2) flush();
  int k = batch.count;
  auto put = [&](std::int32_t j) {  // writes slot k; kept if j is a particle other than self
    __builtin_prefetch(particles + (j < 0 ? 0 : j));
    batch.id[k] = j;
    batch.shift_x[k] = shift.x;
    batch.shift_y[k] = shift.y;
    batch.shift_z[k] = shift.z;
    k += (j >= 0) & (j != self);
  };
  const std::int32_t first = cells.head_[static_cast<std::size_t>(cell)];
  const std::int32_t after_first = cells.next_[static_cast<std::size_t>(first < 0 ? 0 : first)];
  const std::int32_t second = after_first | (first >> 31);  // -1 if the cell is empty
  put(first);
  put(second);
  batch.count = k;
  if (second < 0) return;
  for (std::int32_t j = cells.next_[static_cast<std::size_t>(second)]; j >= 0; j = cells.next_[static_cast<std::size_t>(j)]) {
    if (batch.count == PairBatch::capacity) flush();
    k = batch.count;
    put(j);
    batch.count = k;
  }
}

}  // namespace

std::int32_t Simulation::earliest_partner(const Particle& p, PairBatch& batch, double& best) const {
  const double now = data_.time, g = geometry_.gravity;
  const int n = batch.count;
  for (int k = 0; k < n; ++k) {
    Vec3 rj, vj;
    state_at(data_.particles[static_cast<std::size_t>(batch.id[k])], now, g, rj, vj);
    const Vec3 shift{batch.shift_x[k], batch.shift_y[k], batch.shift_z[k]};
    const Vec3 r = p.r - rj - shift, v = p.v - vj;
    batch.rx[k] = r.x;
    batch.ry[k] = r.y;
    batch.rz[k] = r.z;
    batch.vx[k] = v.x;
    batch.vy[k] = v.y;
    batch.vz[k] = v.z;
  }
  pair_contact_delays(batch);
  std::int32_t partner = -1;
  for (int k = 0; k < n; ++k) {
    const bool earlier = batch.delay[k] < best;
    best = earlier ? batch.delay[k] : best;
    partner = earlier ? batch.id[k] : partner;
  }
  batch.count = 0;
  return partner;
}

void Simulation::predict(std::int32_t i) {
  const Particle& p = data_.particles[i];
  const double now = data_.time;
  const int c = cells_.cell(i);
  Event event;
  std::int32_t direction = 0;
  const double cell_delay = cell_crossing_delay(p, c, direction);
  event.cell_direction = static_cast<std::int8_t>(direction);
  double best = never;
  // Three passes: collect the neighbours (prefetching their states), bring them to now in
  // structure-of-arrays form, then test them all at once (pair_contact_delays vectorises). The
  // states are fetched from memory in parallel (at large N each is a cache miss), and the
  // earliest contact in visiting order is the one a single pass would find.
  PairBatch batch;
  auto flush = [&] {
    const std::int32_t found = earliest_partner(p, batch, best);
    if (found >= 0) event.partner = found;
  };
  cells_.for_each_neighbor_cell(c, [&](int cell, const Vec3& shift) {
    collect_cell(batch, cells_, data_.particles.data(), cell, shift, i, flush);
  });
  flush();
  if (best < never) event.partner_counter = data_.particles[static_cast<std::size_t>(event.partner)].counter;
  predict_walls(i, event, best, cell_delay);
  event.time = now + best;
  event.cell_time = now + cell_delay;
  data_.events[i] = event;
  schedule(i, event.next());
}

void Simulation::predict_walls(std::int32_t i, Event& event, double& best, double cell_delay) {
  if (geometry_.periodic_z) return;
  const Particle& p = data_.particles[i];
  const double now = data_.time;
  const int c = cells_.cell(i);
  const int iz = cells_.iz(c);
  if (iz == cells_.nz() - 1) {
    const double dt = rise_delay(p.r.z, p.v.z, geometry_.gravity, geometry_.height - 0.5);
    if (dt < best) { best = dt; event.kind = EventKind::ceiling; }
  }
  // Only the rows the plate (and a particle on it) can reach need the plate search, and
  // only up to the earliest other event.
  if (iz * cells_.edge_z() < geometry_.plate_top() + 0.5) {
    const double horizon = now + std::min(best, cell_delay);
    const double t = plate_finder_.first_contact(p.r.z, p.v.z, now, horizon, geometry_);
    if (t - now < best) { best = t - now; event.kind = EventKind::plate; }
  }
}

// The particle's trajectory did not change, so its known collision stays valid; only the
// cells that just became neighbours, and the walls near the new cell, can add an earlier one.
void Simulation::predict_after_crossing(std::int32_t i, int direction) {
  const Particle& p = data_.particles[i];
  const double now = data_.time;
  const int c = cells_.cell(i);
  Event event = data_.events[i];
  std::int32_t next_direction = 0;
  const double cell_delay = cell_crossing_delay(p, c, next_direction);
  event.cell_direction = static_cast<std::int8_t>(next_direction);
  double best = event.time - now;
  PairBatch batch;
  auto flush = [&] {
    const std::int32_t found = earliest_partner(p, batch, best);
    if (found >= 0) {
      event.kind = EventKind::pair;
      event.partner = found;
      event.partner_counter = data_.particles[static_cast<std::size_t>(found)].counter;
    }
  };
  // (i itself is in none of the new cells: the box is at least three cells across.)
  cells_.for_each_cell_in_new_face(c, direction / 2, (direction & 1) ? 1 : -1,
                                   [&](int cell, const Vec3& shift) {
    collect_cell(batch, cells_, data_.particles.data(), cell, shift, -1, flush);
  });
  flush();
  if (!(event.kind == EventKind::plate && event.time < never)) predict_walls(i, event, best, cell_delay);
  event.time = now + best;
  event.cell_time = now + cell_delay;
  data_.events[i] = event;
  schedule(i, event.next());
}

}  // namespace shaker::md
