// The indexed binary heap against a plain sorted reference under random key changes.
#include <algorithm>
#include <cstdio>
#include <map>
#include <type_traits>
#include <utility>

#include "md/calendar_queue.hpp"
#include "md/event_queue.hpp"
#include "md/initial_states.hpp"
#include "md_test_support.hpp"

namespace shaker::md {
namespace {

/// Random key changes like the event loop's; returns the number of wrong pops. With `crowd`,
/// a quarter of the starting keys lie within 1e-12 of zero (like the lattice start's contacts),
/// so that one calendar bucket holds hundreds of entries. `deferred`: the calendar queue's
/// deferred insertion.
template <class Queue> int wrong_pops_against_sorted_reference(bool crowd = false, bool deferred = false) {
  const std::int32_t n = 2000;
  Queue heap;
  heap.reset(static_cast<std::size_t>(n));
  if constexpr (std::is_same_v<Queue, CalendarQueue>) heap.set_deferred(deferred);
  std::map<std::int32_t, double> keys;  // the reference: all current keys
  Random random(99);
  for (std::int32_t id = 0; id < n; ++id) {
    const double t = crowd && id % 4 == 0 ? random.uniform(0.0, 1e-12) : random.uniform(0.0, 10.0);
    heap.update(id, t);
    keys[id] = t;
  }
  int mismatches = 0;
  double now = 0.0;
  for (int step = 0; step < 200000; ++step) {
    // The reference minimum, ties by id, as the heap promises.
    const auto best = std::min_element(keys.begin(), keys.end(), [](const auto& a, const auto& b) {
      return a.second < b.second || (a.second == b.second && a.first < b.first);
    });
    if (heap.top() != best->first || heap.top_time() != best->second) ++mismatches;
    now = best->second;
    // Like the event loop: the popped particle and a random other one get new keys, some
    // equal to the current time (ties) and some later.
    const std::int32_t other = static_cast<std::int32_t>(random.below(n));
    for (std::int32_t id : {best->first, other}) {
      const double t = random.uniform() < 0.1 ? now
                       : crowd && now < 1e-12 && random.uniform() < 0.5 ? now + random.uniform(0.0, 1e-13)
                                                                         : now + random.uniform(0.0, 1.0);
      heap.update(id, t);
      keys[id] = t;
    }
    if ((step % 20000 == 0 || (crowd && step < 2000 && step % 50 == 0)) && !heap.consistent()) ++mismatches;
  }
  return mismatches + (heap.consistent() ? 0 : 1);
}

TEST(MdEventQueue, PopOrderMatchesSortedReferenceUnderRandomUpdates) {
  EXPECT_EQ(wrong_pops_against_sorted_reference<IndexedHeap>(), 0);
  EXPECT_EQ(wrong_pops_against_sorted_reference<CalendarQueue>(), 0);
  // A crowded bucket is sorted into a heap when the scan reaches it: the same order.
  EXPECT_EQ(wrong_pops_against_sorted_reference<CalendarQueue>(true), 0);
  // Deferred insertion (large runs): pending entries count in the minimum search.
  EXPECT_EQ(wrong_pops_against_sorted_reference<CalendarQueue>(false, true), 0);
  EXPECT_EQ(wrong_pops_against_sorted_reference<CalendarQueue>(true, true), 0);
}

bool identical(const SimulationData& a, const SimulationData& b) {
  if (a.particles.size() != b.particles.size() || a.time != b.time) return false;
  for (std::size_t i = 0; i < a.particles.size(); ++i) {
    const Particle &p = a.particles[i], &q = b.particles[i];
    if (p.r.x != q.r.x || p.r.y != q.r.y || p.r.z != q.r.z || p.v.x != q.v.x ||
        p.v.y != q.v.y || p.v.z != q.v.z || p.t != q.t || a.events[i].next() != b.events[i].next())
      return false;
  }
  return a.tally.pair == b.tally.pair && a.tally.cell == b.tally.cell && a.tally.plate == b.tally.plate;
}

/// A run's starting point: the two the trajectory-equality tests below use.
struct Start {
  Geometry geometry;
  CollisionRules rules;
  State state;
};

/// Elastic gas of n particles at nu = 0.3 in a periodic box without gravity.
Start elastic_gas(std::size_t n, std::uint64_t seed) {
  Start s;
  s.geometry = periodic_box(n, 0.3);
  s.rules.restitution = Restitution{Restitution::Kind::constant, 1.0};
  s.state = homogeneous_gas(s.geometry, n, 0.3, 1.0, seed);
  return s;
}

const ShakerKinematics base_shaker{3.0, 0.095};

/// The base case's layer (Gamma = 3, f = 0.095, 3937 particles, e = 0.9) at rest on the plate.
Start vibrated_layer(std::uint64_t seed) {
  Start s;
  s.geometry.plate = base_shaker;
  s.rules.restitution = Restitution{Restitution::Kind::constant, 0.9};
  s.state = flat_layer(s.geometry, 3937, seed);
  return s;
}

TEST(MdEventQueue, CalendarQueueGivesTheHeapsTrajectoryInTheGas) {
  const Start s = elastic_gas(2000, 4);
  Simulation fast(s.geometry, s.rules, s.state, QueueKind::calendar),
      reference(s.geometry, s.rules, s.state, QueueKind::heap);
  fast.advance_to(50.0);
  reference.advance_to(50.0);
  std::printf("measured: %llu collisions each\n", static_cast<unsigned long long>(fast.tally().pair));
  EXPECT_GT(fast.tally().pair, 200000u);
  EXPECT_TRUE(fast.queue_consistent());
  EXPECT_TRUE(identical(fast.save(), reference.save()));
}

TEST(MdEventQueue, CalendarQueueGivesTheHeapsTrajectoryInTheVibratedLayer) {
  const Start s = vibrated_layer(8);
  Simulation fast(s.geometry, s.rules, s.state, QueueKind::calendar),
      reference(s.geometry, s.rules, s.state, QueueKind::heap);
  fast.advance_to(1.5 / base_shaker.frequency());
  reference.advance_to(1.5 / base_shaker.frequency());
  EXPECT_GT(fast.tally().pair, 300000u);
  EXPECT_TRUE(fast.queue_consistent());
  EXPECT_TRUE(identical(fast.save(), reference.save()));
}

// The software pipelining of large runs only prefetches: forced on at small N (with both
// queues, in the gas and in the vibrated layer with its walls and open top row), every state,
// event and count is the same as without it.
TEST(MdEventQueue, LookaheadPrefetchingLeavesTheTrajectoryUnchanged) {
  const Start gas = elastic_gas(2000, 5);
  for (const QueueKind queue : {QueueKind::calendar, QueueKind::heap}) {
    Simulation with(gas.geometry, gas.rules, gas.state, queue),
        without(gas.geometry, gas.rules, gas.state, queue);
    EXPECT_FALSE(without.lookahead());  // off by default at this size
    with.set_lookahead(true);
    with.advance_to(20.0);
    without.advance_to(20.0);
    EXPECT_GT(with.tally().pair, 100000u);
    EXPECT_TRUE(with.queue_consistent());
    EXPECT_TRUE(identical(with.save(), without.save()));
  }
  const Start layer = vibrated_layer(9);
  Simulation with(layer.geometry, layer.rules, layer.state),
      without(layer.geometry, layer.rules, layer.state);
  with.set_lookahead(true);
  with.advance_to(1.0 / base_shaker.frequency());
  without.advance_to(1.0 / base_shaker.frequency());
  EXPECT_GT(with.tally().pair, 100000u);
  EXPECT_TRUE(identical(with.save(), without.save()));
}

}  // namespace
}  // namespace shaker::md
