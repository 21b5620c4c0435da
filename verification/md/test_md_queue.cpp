// The indexed binary heap against a plain sorted reference under random key changes.
#include <algorithm>
#include <map>
#include <utility>

#include "md/event_queue.hpp"
#include "md/initial_states.hpp"
#include "md_test_support.hpp"

namespace shaker::md {
namespace {

TEST(MdEventQueue, PopOrderMatchesSortedReferenceUnderRandomUpdates) {
  const std::int32_t n = 2000;
  IndexedHeap heap;
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
  EXPECT_EQ(mismatches, 0);
  EXPECT_TRUE(heap.consistent());
}

}  // namespace
}  // namespace shaker::md
