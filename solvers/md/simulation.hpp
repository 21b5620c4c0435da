#pragma once
// The event loop: pop the earliest pending event, bring the particles involved to its time,
// apply the rule, predict their next events. Stale events are recognised lazily: a pair event
// remembers the partner's collision counter at prediction time.
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/errors.hpp"
#include "md/calendar_queue.hpp"
#include "md/cell_list.hpp"
#include "md/collision_rules.hpp"
#include "md/event_prediction.hpp"
#include "md/event_queue.hpp"
#include "md/geometry.hpp"
#include "md/height_counts.hpp"
#include "md/particles.hpp"

namespace shaker::md {

enum class EventKind : std::uint8_t { pair, plate, ceiling, cell };

/// A particle's pending events: its earliest known collision (pair or wall; time = never if
/// none) and its next cell crossing, kept apart so that a cell crossing only needs to look at
/// the 9 cells that became neighbours. The queue holds the earlier of the two.
struct Event {
  double time = never;
  double cell_time = never;
  std::int32_t partner = -1;         ///< pair: the other particle
  std::uint32_t partner_counter = 0; ///< pair: partner's collision counter when predicted
  EventKind kind = EventKind::pair;  ///< pair, plate or ceiling
  std::int8_t cell_direction = 0;    ///< 2 axis + (1 if upwards)
  double next() const { return cell_time < time ? cell_time : time; }
};

/// Running totals of a run (all kept in checkpoints).
struct Tally {
  std::uint64_t pair = 0, plate = 0, ceiling = 0, cell = 0, stale = 0;
  std::uint64_t guard_activations = 0, grazes = 0;
  double plate_work = 0.0, pair_loss = 0.0, wall_loss = 0.0;
  double virial = 0.0;  ///< sum of r_ab . (impulse on a) over pair collisions
  std::uint64_t collisions() const { return pair + plate + ceiling; }
};

/// Everything that determines the future of a run: a checkpoint stores exactly this.
struct SimulationData {
  double time = 0.0;
  std::vector<Particle> particles;
  std::vector<Event> events;
  /// Time of each particle's last pair or wall collision (TC guard); only collisions touch it,
  /// so it is kept out of the particles' cache lines.
  std::vector<double> last_collision;
  std::vector<std::int32_t> cell_head, cell_next, cell_prev, cell_of;
  Tally tally;
};

/// Collapse detector (guard off): a particle whose collisions follow each other within
/// collapse_interval more than collapse_streak times in a row is taken to be collapsing.
inline constexpr double collapse_interval = 1e-9;
inline constexpr std::uint32_t collapse_streak = 100;
/// The same for the whole system: more than this many events per particle (plus the floor)
/// while the time advances by less than collapse_interval.
inline constexpr std::uint64_t stalled_events_per_particle = 100;
inline constexpr std::uint64_t stalled_events_floor = 10000;

/// Which future-event list to use: the calendar queue (the default: faster than the heap at
/// every N measured, docs/performance.md) or the indexed binary heap (the simple reference). Both pop events in the
/// same order, so a run is identical with either.
enum class QueueKind { calendar, heap };

class Simulation {
 public:
  /// A fresh run from particle states (cells and events are built here).
  Simulation(const Geometry& geometry, const CollisionRules& rules, const State& initial,
             QueueKind queue = QueueKind::calendar);
  /// A continued run: cells, events and counters exactly as saved.
  Simulation(const Geometry& geometry, const CollisionRules& rules, SimulationData saved,
             QueueKind queue = QueueKind::calendar);

  /// Processes every event with time <= t, then sets the clock to t.
  void advance_to(double t);
  /// Processes exactly one event (tests and benchmarks).
  void step();

  double time() const { return data_.time; }
  const Geometry& geometry() const { return geometry_; }
  const Tally& tally() const { return data_.tally; }
  /// A copy of the complete state, cell lists included (for checkpoints).
  SimulationData save() const;
  const std::vector<Particle>& particles() const { return data_.particles; }
  std::size_t size() const { return data_.particles.size(); }
  void set_restitution(const Restitution& restitution) { rules_.restitution = restitution; }
  const CollisionRules& rules() const { return rules_; }

  /// Positions (wrapped into the box in x, y) and velocities of all particles at t >= time().
  void positions_at(double t, std::vector<Vec3>& r, std::vector<Vec3>& v) const;
  double kinetic_energy(double t) const;
  double potential_energy(double t) const;  ///< g z in the lab frame
  /// Pairs closer than 1 - tolerance at time t (cell-list search).
  std::size_t count_overlaps(double t, double tolerance) const;
  /// The same for positions already computed by positions_at(time(), ...).
  std::size_t count_overlaps(const std::vector<Vec3>& r, double tolerance) const;
  /// Starts counting, for each of these lab-frame heights, upward crossings and distinct
  /// particles per shaker cycle at time() (counts start at zero; what flights under way did
  /// before is not counted). Cycle c is [c / cycle_frequency, (c + 1) / cycle_frequency).
  void start_height_counts(std::vector<double> heights, double cycle_frequency) {
    height_counts_.start(std::move(heights), cycle_frequency, geometry_.gravity, data_.time, data_.particles);
  }
  /// Upward crossings of each height since start_height_counts, up to t >= time(): flights
  /// still under way are counted up to t without changing any particle.
  std::vector<std::uint64_t> crossings_at(double t) const { return height_counts_.crossings_at(data_.particles, t); }
  /// For each height, the sum over the cycles since start_height_counts of the distinct
  /// particles at or above it at some instant of the cycle, up to t >= time().
  std::vector<std::uint64_t> distinct_particles_at(double t) const {
    return height_counts_.distinct_particles_at(data_.particles, t);
  }
  /// Heap property, index, and every pending event in the future of time().
  bool queue_consistent() const;
  std::size_t bytes_per_particle() const;
  /// Software pipelining across events (see prefetch_stage1, and the calendar queue's deferred
  /// insertion): on by default from
  /// lookahead_min_particles particles, where memory latency dominates. It only prefetches, so
  /// a run is the same with or without (tested); benchmarks switch it to compare.
  void set_lookahead(bool on) {
    lookahead_ = lookahead_members_ = on;
    calendar_.set_deferred(on);
  }
  bool lookahead() const { return lookahead_; }

 private:
  void initialise_queue();
  void predict(std::int32_t i);
  void predict_after_crossing(std::int32_t i, int direction);
  /// Tests p against the collected candidates (brought to now here, with their image shifts);
  /// returns the first candidate whose contact is earlier than best and sets best, or -1.
  /// Empties the batch.
  std::int32_t earliest_partner(const Particle& p, PairBatch& batch, double& best) const;
  /// Finds wall contacts of i earlier than `best` (a delay); updates event and best.
  void predict_walls(std::int32_t i, Event& event, double& best, double cell_delay);
  double cell_crossing_delay(const Particle& p, int cell, std::int32_t& direction) const;
  void cross_cell(std::int32_t i, std::int32_t direction);
  /// Counts a collision of i (at now; `before`: i's local time before this event).
  void note_collision(std::int32_t i, std::int32_t partner, double before);
  /// The time of i's last collision where it matters, for a test now - last < window; `before`
  /// is i's local time before this event. The last collision is never later than any local
  /// time since (a collision happens at the particle's local time), so if now - before >= window
  /// the test fails either way and the array (a cache miss at large N) is not read.
  double last_collision(std::int32_t i, double before, double window) const {
    return data_.time - before < window ? data_.last_collision[static_cast<std::size_t>(i)] : no_collision_yet;
  }
  /// Renumbers the particles in cell order (memory locality); called every
  /// sort_interval * N pair collisions.
  void sort_by_cell();
  static constexpr std::uint64_t sort_interval = 2;
  /// Brings particle i to now, counting what its free flight reached on the way.
  void update(std::int32_t i, double now);
  /// Prefetches what the next events will read (lookahead_).
  void prefetch_ahead(const Event& event);
  /// The pair collision of `event` at the current time (i already advanced): false if the
  /// partner has moved since it was predicted (a stale event; nothing is predicted).
  bool pair_event(std::int32_t i, const Event& event, double before_i);
  /// The plate or ceiling collision of particle i at the current time (i already advanced).
  void wall_event(std::int32_t i, EventKind kind, double before_i);

  /// Software pipelining across events (large N, where every event waits for memory): while
  /// event k is processed, what the next events will read is prefetched in stages, each stage
  /// reading only what an earlier one brought in. Stage 1, for entries the calendar queue's
  /// cursor meets a few buckets ahead, and for event k + 3: their event, state and cell.
  /// Stage 2, for event k + 2 (the guesses come from the queue): the heads of its 27 cells,
  /// and the partner's state, event and cell (stage 2 for k + 3 as well would read events that
  /// have not arrived yet: slower, docs/performance.md). Stage 3, for event k + 1: the
  /// first member of each of its cells, and the partner's cell heads; event k itself prefetches
  /// its partner's first members before the collision. Hints only: the same results either way.
  void prefetch_stage1(std::int32_t a) const;
  void prefetch_stage2(std::int32_t a) const;
  void prefetch_stage3(std::int32_t a) const;
  /// Prefetches the state and next link of the first particle of each cell around c (their
  /// heads are read), or of the 9 cells of a new face if axis >= 0.
  void prefetch_members(int c, int axis = -1, int step = 0) const;
  static constexpr std::size_t lookahead_min_particles = 30000;
  /// Stage 3 (the members of the cells) only pays once the cell lists no longer fit in the
  /// cache (docs/performance.md).
  static constexpr std::size_t lookahead_members_min_particles = 100000;
  bool lookahead_ = false, lookahead_members_ = false;

  Geometry geometry_;
  CollisionRules rules_;
  SimulationData data_;
  CellList cells_;
  /// An empty queue of the chosen kind for n particles, and the lookahead its size calls for.
  void reset_queue(std::size_t n);
  void schedule(std::int32_t i, double time) {
    if (use_calendar_) calendar_.update(i, time);
    else heap_.update(i, time);
  }
  bool use_calendar_ = false;
  IndexedHeap heap_;
  CalendarQueue calendar_;
  PlateContactFinder plate_finder_;
  HeightCounts height_counts_;
};

}  // namespace shaker::md
