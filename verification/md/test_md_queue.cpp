// The indexed binary heap against a plain sorted reference under random key changes.
#include <algorithm>
#include <cstdio>
#include <map>
#include <utility>

#include "md/calendar_queue.hpp"
#include "md/event_queue.hpp"
#include "md/initial_states.hpp"
#include "md_test_support.hpp"

namespace shaker::md {
namespace {

/// Random key changes like the event loop's; returns the number of wrong pops.
template <class Queue> int wrong_pops_against_sorted_reference() {
  const std::int32_t n = 2000;
  Queue heap;
  heap.reset(static_cast<std::size_t>(n));
  std::map<std::int32_t, double> keys;  // the reference: all current keys
  Random random(99);
  for (std::int32_t id = 0; id < n; ++id) {
    const double t = random.uniform(0.0, 10.0);
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
      const double t = random.uniform() < 0.1 ? now : now + random.uniform(0.0, 1.0);
      heap.update(id, t);
      keys[id] = t;
    }
    if (step % 20000 == 0 && !heap.consistent()) ++mismatches;
  }
  return mismatches + (heap.consistent() ? 0 : 1);
}

TEST(MdEventQueue, PopOrderMatchesSortedReferenceUnderRandomUpdates) {
  EXPECT_EQ(wrong_pops_against_sorted_reference<IndexedHeap>(), 0);
  EXPECT_EQ(wrong_pops_against_sorted_reference<CalendarQueue>(), 0);
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

TEST(MdEventQueue, CalendarQueueGivesTheHeapsTrajectoryInTheGas) {
  const std::size_t n = 2000;
  const Geometry g = testing::periodic_box(n, 0.3);
  CollisionRules rules;
  rules.restitution = Restitution{Restitution::Kind::constant, 1.0};
  const State start = homogeneous_gas(g, n, 0.3, 1.0, 4);
  Simulation fast(g, rules, start, QueueKind::calendar), reference(g, rules, start, QueueKind::heap);
  fast.advance_to(50.0);
  reference.advance_to(50.0);
  std::printf("measured: %llu collisions each\n", static_cast<unsigned long long>(fast.tally().pair));
  EXPECT_GT(fast.tally().pair, 200000u);
  EXPECT_TRUE(fast.queue_consistent());
  EXPECT_TRUE(identical(fast.save(), reference.save()));
}

TEST(MdEventQueue, CalendarQueueGivesTheHeapsTrajectoryInTheVibratedLayer) {
  const ShakerKinematics shaker{3.0, 0.095};
  Geometry g;
  g.plate = PlateMotion::from(shaker);
  CollisionRules rules;
  rules.restitution = Restitution{Restitution::Kind::constant, 0.9};
  const State start = flat_layer(g, 3937, 8);
  Simulation fast(g, rules, start, QueueKind::calendar), reference(g, rules, start, QueueKind::heap);
  fast.advance_to(1.5 / shaker.f);
  reference.advance_to(1.5 / shaker.f);
  EXPECT_GT(fast.tally().pair, 300000u);
  EXPECT_TRUE(fast.queue_consistent());
  EXPECT_TRUE(identical(fast.save(), reference.save()));
}

// The software pipelining of large runs only prefetches: forced on at small N (with both
// queues, in the gas and in the vibrated layer with its walls and open top row), every state,
// event and count is the same as without it.
TEST(MdEventQueue, LookaheadPrefetchingLeavesTheTrajectoryUnchanged) {
  const std::size_t n = 2000;
  const Geometry g = testing::periodic_box(n, 0.3);
  CollisionRules rules;
  rules.restitution = Restitution{Restitution::Kind::constant, 1.0};
  const State start = homogeneous_gas(g, n, 0.3, 1.0, 5);
  for (const QueueKind queue : {QueueKind::calendar, QueueKind::heap}) {
    Simulation with(g, rules, start, queue), without(g, rules, start, queue);
    EXPECT_FALSE(without.lookahead());  // off by default at this size
    with.set_lookahead(true);
    with.advance_to(20.0);
    without.advance_to(20.0);
    EXPECT_GT(with.tally().pair, 100000u);
    EXPECT_TRUE(with.queue_consistent());
    EXPECT_TRUE(identical(with.save(), without.save()));
  }
  const ShakerKinematics shaker{3.0, 0.095};
  Geometry box;
  box.plate = PlateMotion::from(shaker);
  rules.restitution = Restitution{Restitution::Kind::constant, 0.9};
  const State layer = flat_layer(box, 3937, 9);
  Simulation with(box, rules, layer), without(box, rules, layer);
  with.set_lookahead(true);
  with.advance_to(1.0 / shaker.f);
  without.advance_to(1.0 / shaker.f);
  EXPECT_GT(with.tally().pair, 100000u);
  EXPECT_TRUE(identical(with.save(), without.save()));
}

}  // namespace
}  // namespace shaker::md
