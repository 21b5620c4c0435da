#pragma once
// A bounded calendar queue in the style of Paul (J. Comput. Phys. 221, 615, 2007): one
// pending time per particle, hashed into buckets of width w covering a window of the near
// future; later times wait in an overflow list. Buckets are scanned for their exact minimum
// (ties by particle index), so the pop order is the same total order as IndexedHeap's and a
// run gives the same trajectory with either queue. When the window is used up, every entry is
// in the overflow list; the width is then re-estimated from the pending times and the window
// restarts at the earliest one (O(N) once per window, about N events). A crowded current
// bucket (more than crowded_bucket entries, e.g. the lattice start's thousands of contacts at
// t ~ 1e-14 in one bucket) is not rescanned at every pop: its entries move into a binary heap
// (same order) that serves the pops, and the inserts into that bucket, until it is empty.
//
// Deferred insertion (set_deferred, for large N): linking an entry into its bucket reads the
// bucket's head and writes the old head's node, two cache misses at large N that nothing can
// prefetch before the time is known. With deferral an update only prefetches them and leaves
// the entry pending; it is linked when `pending_capacity` later updates have come (about one
// event later, the lines have arrived). The minimum search counts pending entries as members
// of the bucket their time belongs to, so the pop order is exactly the same.
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "md/prefetch.hpp"

namespace shaker::md {

class CalendarQueue {
 public:
  void reset(std::size_t n);
  void update(std::int32_t id, double time);
  std::int32_t top() {
    if (!cached_valid_) find_minimum();
    return cached_;
  }
  double top_time() {
    if (!cached_valid_) find_minimum();
    return cached_ < 0 ? std::numeric_limits<double>::infinity() : node_[cached_].time;
  }
  /// Guesses of the next pops after top(): fills next[0..2] (-1 where none), for prefetching
  /// only: the three earliest entries of the current bucket other than the top and `also` (the
  /// top's partner, whose entry is about to move), else the first entries of the next buckets.
  /// Call after top(); reads only what the last scan brought into the cache.
  void peek_after_top(std::int32_t also, std::int32_t next[3]) const;
  /// One step of a cursor that walks the lists of the next buckets ahead of the scan: fills
  /// reached[0..1] with the entries it reaches (their queue entries now being prefetched) and
  /// returns how many: the head of the next non-empty bucket (the heads are contiguous, no
  /// wait), and the successor of an entry reached by an earlier call (its node was prefetched
  /// then: following two links in one call makes the second wait for memory; docs/performance.md).
  /// A hint: the cursor never changes the order.
  int walk_ahead(std::int32_t reached[2]);
  /// Prefetches the queue's entry of id (a hint: nothing is read).
  void prefetch(std::int32_t id) const {
    const Node& node = node_[static_cast<std::size_t>(id)];
    md::prefetch(&node.time);
    md::prefetch(&node.overflow_slot);  // the other line, if the node straddles two
  }
  /// Deferred insertion on or off (the order of pops is the same either way).
  void set_deferred(bool on) {
    if (!on) flush_pending(0);
    deferred_ = on;
  }
  bool empty() const { return size_ == 0; }
  std::size_t size() const { return size_; }
  bool consistent() const;
  std::size_t bytes_per_entry() const {
    return sizeof(Node) + 2 * sizeof(std::int32_t);  // + buckets
  }

 private:
  static constexpr std::int32_t in_overflow = -2, absent = -1, in_heap = -3, pending = -4;
  static constexpr int crowded_bucket = 32;
  bool less(std::int32_t a, std::int32_t b) const {
    return node_[a].time < node_[b].time || (node_[a].time == node_[b].time && a < b);
  }
  void unlink(std::int32_t id);
  void place(std::int32_t id);
  void find_minimum();
  void restart_window();
  /// Links pending entries, the oldest first, until at most `keep` are left.
  void flush_pending(int keep);
  /// Whether a pending entry's time belongs to the current bucket (or before it).
  bool in_current_bucket(std::int32_t id) const {
    return std::floor((node_[id].time - base_) / width_) < static_cast<double>(current_) + 1.0;
  }
  /// The heap of a crowded current bucket: ids ordered by less(), each node's `next` holding
  /// its position.
  void heap_push(std::int32_t id);
  void heap_remove(std::int32_t id);
  void heap_sift(std::size_t at);
  void heap_set(std::size_t at, std::int32_t id) {
    heap_[at] = id;
    node_[id].next = static_cast<std::int32_t>(at);
  }
  /// Moves the entries of the current bucket's list into the heap.
  void sort_current_bucket();

  /// Everything the queue keeps of one entry in one place (24 bytes: a scan or an update
  /// touches one line per entry, not five).
  struct Node {
    double time;
    std::int32_t where;          ///< bucket, in_overflow, in_heap, pending or absent
    std::int32_t next, prev;     ///< links in the bucket's list (next: position in heap_)
    std::int32_t overflow_slot;  ///< position in overflow_ when there
  };
  std::vector<Node> node_;
  std::vector<std::int32_t> head_;      // per bucket
  std::vector<std::int32_t> overflow_;  // ids
  std::vector<std::int32_t> heap_;      // ids of the crowded current bucket (if sorted)
  bool sorted_ = false;                 // the current bucket lives in heap_
  static constexpr int pending_capacity = 2;
  std::int32_t pending_[pending_capacity + 1] = {};  // ids of pending entries, oldest first
  int pending_count_ = 0;
  bool deferred_ = false;
  std::int32_t current_ = 0;            // bucket holding the earliest times
  double base_ = 0.0, width_ = 1.0;
  std::size_t size_ = 0;
  std::int32_t cached_ = -1;
  // walk_ahead's cursor: the next bucket whose head it takes, and the entries reached whose
  // links it has yet to follow (oldest first).
  std::int32_t walk_bucket_ = 0;
  std::int32_t walk_links_[4] = {};
  int walk_link_count_ = 0;
  bool cached_valid_ = false;
};

}  // namespace shaker::md
