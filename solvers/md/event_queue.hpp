#pragma once
// The future event list: one pending event per particle, keyed by its time (ties broken by
// particle index, so the order of events is a total order and a restart replays it exactly).
// IndexedHeap is an indexed binary heap, O(log N) per update.
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

#include "md/prefetch.hpp"

namespace shaker::md {

/// Binary-heap sifting, shared by IndexedHeap and the calendar queue's crowded bucket. `place(k,
/// value)` stores value at position k and records the position wherever its heap keeps it.
/// Moves heap[at] up to its place; returns where it ended.
template <class T, class Less, class Place>
std::size_t sift_up(const T* heap, std::size_t at, Less less, Place place) {
  const T value = heap[at];
  while (at > 0) {
    const std::size_t parent = (at - 1) / 2;
    if (!less(value, heap[parent])) break;
    place(at, heap[parent]);
    at = parent;
  }
  place(at, value);
  return at;
}
/// Moves heap[at] of a heap of `size` entries down to its place.
template <class T, class Less, class Place>
void sift_down(const T* heap, std::size_t size, std::size_t at, Less less, Place place) {
  const T value = heap[at];
  for (;;) {
    std::size_t child = 2 * at + 1;
    if (child >= size) break;
    if (child + 1 < size && less(heap[child + 1], heap[child])) ++child;
    if (!less(heap[child], value)) break;
    place(at, heap[child]);
    at = child;
  }
  place(at, value);
}

class IndexedHeap {
 public:
  void reset(std::size_t n) {
    heap_.clear();
    position_.assign(n, -1);
  }
  bool empty() const { return heap_.empty(); }
  std::int32_t top() const { return heap_.front().id; }
  double top_time() const {
    return heap_.empty() ? std::numeric_limits<double>::infinity() : heap_.front().time;
  }
  /// Guesses of the next pops after top(): next[0..2] (-1 where none), for prefetching only:
  /// the root's children, the earlier first (the heap keeps no cheap third; `also` unused).
  void peek_after_top(std::int32_t /*also*/, std::int32_t next[3]) const {
    next[0] = next[1] = next[2] = -1;
    if (heap_.size() > 1) next[0] = heap_[1].id;
    if (heap_.size() > 2) {
      next[1] = heap_[2].id;
      if (less(heap_[2], heap_[1])) std::swap(next[0], next[1]);
    }
  }
  /// Prefetches the heap position of id (a hint: nothing is read).
  void prefetch(std::int32_t id) const { md::prefetch(&position_[static_cast<std::size_t>(id)]); }
  /// Inserts the particle or changes its key.
  void update(std::int32_t id, double time) {
    std::int32_t at = position_[id];
    if (at < 0) {
      at = static_cast<std::int32_t>(heap_.size());
      heap_.push_back({time, id});
      position_[id] = at;
      sift_up(at);
      return;
    }
    const bool earlier = less({time, id}, heap_[at]);
    heap_[at].time = time;
    if (earlier) sift_up(at);
    else sift_down(at);
  }
  /// Checks the heap property and the index (for the end-of-run consistency check).
  bool consistent() const {
    for (std::size_t k = 0; k < heap_.size(); ++k) {
      if (position_[heap_[k].id] != static_cast<std::int32_t>(k)) return false;
      if (k > 0 && less(heap_[k], heap_[(k - 1) / 2])) return false;
    }
    return true;
  }
  std::size_t size() const { return heap_.size(); }
  std::size_t bytes_per_entry() const { return sizeof(Entry) + sizeof(std::int32_t); }

 private:
  struct Entry {
    double time;
    std::int32_t id;
  };
  static bool less(const Entry& a, const Entry& b) {
    return a.time < b.time || (a.time == b.time && a.id < b.id);
  }
  auto placer() {
    return [this](std::size_t at, const Entry& e) {
      heap_[at] = e;
      position_[e.id] = static_cast<std::int32_t>(at);
    };
  }
  void sift_up(std::int32_t at) {
    md::sift_up(heap_.data(), static_cast<std::size_t>(at), less, placer());
  }
  void sift_down(std::int32_t at) {
    md::sift_down(heap_.data(), heap_.size(), static_cast<std::size_t>(at), less, placer());
  }
  std::vector<Entry> heap_;
  std::vector<std::int32_t> position_;
};

}  // namespace shaker::md
