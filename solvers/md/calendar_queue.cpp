#include "md/calendar_queue.hpp"

#include <algorithm>
#include <cmath>

#include "md/event_queue.hpp"

namespace shaker::md {

void CalendarQueue::reset(std::size_t n) {
  node_.assign(n, Node{std::numeric_limits<double>::infinity(), absent, -1, -1, -1});
  std::size_t buckets = 16;
  while (buckets < n) buckets *= 2;
  head_.assign(buckets, -1);
  overflow_.clear();
  heap_.clear();
  sorted_ = false;
  pending_count_ = 0;
  current_ = static_cast<std::int32_t>(buckets);  // no window yet: the first pop builds one
  base_ = 0.0;
  size_ = 0;
  walk_bucket_ = 0;
  walk_link_count_ = 0;
  cached_valid_ = false;
}

// (Inlined into update, the hot path: out of line it is measurably slower, docs/performance.md.)
[[gnu::always_inline]] inline void CalendarQueue::unlink(std::int32_t id) {
  const std::int32_t w = node_[id].where;
  if (w == absent) return;
  if (w == pending) {
    int k = 0;
    while (pending_[k] != id) ++k;
    for (; k + 1 < pending_count_; ++k) pending_[k] = pending_[k + 1];
    --pending_count_;
  } else if (w == in_heap) {
    heap_remove(id);
  } else if (w == in_overflow) {
    const std::int32_t slot = node_[id].overflow_slot;
    const std::int32_t last = overflow_.back();
    overflow_[static_cast<std::size_t>(slot)] = last;
    node_[last].overflow_slot = slot;
    overflow_.pop_back();
  } else {
    if (node_[id].prev >= 0) node_[node_[id].prev].next = node_[id].next;
    else head_[static_cast<std::size_t>(w)] = node_[id].next;
    if (node_[id].next >= 0) node_[node_[id].next].prev = node_[id].prev;
  }
  node_[id].where = absent;
}

[[gnu::always_inline]] inline void CalendarQueue::place(std::int32_t id) {
  const double nb = static_cast<double>(head_.size());
  const double k = std::floor((node_[id].time - base_) / width_);
  if (!(k < nb) || current_ >= static_cast<std::int32_t>(head_.size())) {
    node_[id].where = in_overflow;
    node_[id].overflow_slot = static_cast<std::int32_t>(overflow_.size());
    overflow_.push_back(id);
    return;
  }
  // Times before the current bucket (only by rounding) go into it: buckets are scanned in full.
  const auto bucket = std::max(current_, static_cast<std::int32_t>(std::max(k, 0.0)));
  if (sorted_ && bucket == current_) {
    heap_push(id);
    return;
  }
  node_[id].where = bucket;
  node_[id].prev = -1;
  node_[id].next = head_[static_cast<std::size_t>(bucket)];
  if (node_[id].next >= 0) node_[node_[id].next].prev = id;
  head_[static_cast<std::size_t>(bucket)] = id;
}

void CalendarQueue::update(std::int32_t id, double time) {
  if (node_[id].where == absent) ++size_;
  unlink(id);
  node_[id].time = time;
  if (deferred_) {
    // Prefetch what linking will touch: the bucket's head now, the old head's node when the
    // entry is linked (by then the head has arrived).
    const double k = std::floor((time - base_) / width_);
    if (k >= 0.0 && k < static_cast<double>(head_.size()))
      md::prefetch(&head_[static_cast<std::size_t>(k)]);
    node_[id].where = pending;
    pending_[pending_count_++] = id;
    flush_pending(pending_capacity);
  } else {
    place(id);
  }
  if (cached_valid_) {
    if (id == cached_) cached_valid_ = false;
    else if (cached_ >= 0 && less(id, cached_)) cached_ = id;
    else if (cached_ < 0) cached_valid_ = false;
  }
}

void CalendarQueue::flush_pending(int keep) {
  if (pending_count_ <= keep) return;
  const int linked = pending_count_ - keep;
  for (int k = 0; k < linked; ++k) place(pending_[k]);
  for (int k = 0; k < keep; ++k) pending_[k] = pending_[k + linked];
  pending_count_ = keep;
}

void CalendarQueue::restart_window() {
  // All entries are in the overflow list here. New width: about two entries per bucket.
  double earliest = std::numeric_limits<double>::infinity(), sum = 0.0;
  std::size_t finite = 0;
  for (std::int32_t id : overflow_) {
    if (!std::isfinite(node_[id].time)) continue;
    earliest = std::min(earliest, node_[id].time);
    sum += node_[id].time;
    ++finite;
  }
  current_ = 0;
  walk_bucket_ = 0;
  walk_link_count_ = 0;
  if (finite == 0) {
    current_ = static_cast<std::int32_t>(head_.size());
    return;
  }
  const double mean_delay = sum / static_cast<double>(finite) - earliest;
  const double nb = static_cast<double>(head_.size());
  width_ = mean_delay > 0.0 ? 4.0 * mean_delay / nb : 1.0;
  base_ = earliest;
  std::vector<std::int32_t> waiting;
  waiting.swap(overflow_);
  for (std::int32_t id : waiting) place(id);
}

void CalendarQueue::find_minimum() {
  cached_valid_ = true;
  cached_ = -1;
  if (size_ == 0) return;
  for (;;) {
    if (current_ >= static_cast<std::int32_t>(head_.size())) {
      flush_pending(0);  // into the overflow list, which the new window distributes
      restart_window();
      if (current_ >= static_cast<std::int32_t>(head_.size())) return;  // only `never` left
    }
    std::int32_t best = -1;
    if (sorted_) {
      if (!heap_.empty()) best = heap_.front();
    } else {
      int count = 0;
      for (std::int32_t id = head_[static_cast<std::size_t>(current_)]; id >= 0; id = node_[id].next, ++count)
        if (best < 0 || less(id, best)) best = id;
      if (count > crowded_bucket) {
        sort_current_bucket();
        continue;
      }
    }
    for (int k = 0; k < pending_count_; ++k)  // members of this bucket not linked yet
      if (in_current_bucket(pending_[k]) && (best < 0 || less(pending_[k], best))) best = pending_[k];
    if (best >= 0) {
      cached_ = best;
      return;
    }
    sorted_ = false;  // (a sorted bucket is used up)
    ++current_;
  }
}

void CalendarQueue::sort_current_bucket() {
  sorted_ = true;
  heap_.clear();
  std::int32_t id = head_[static_cast<std::size_t>(current_)];
  head_[static_cast<std::size_t>(current_)] = -1;
  while (id >= 0) {
    const std::int32_t next = node_[id].next;
    heap_push(id);
    id = next;
  }
}

void CalendarQueue::heap_push(std::int32_t id) {
  node_[id].where = in_heap;
  heap_.push_back(id);
  heap_set(heap_.size() - 1, id);
  heap_sift(heap_.size() - 1);
}

void CalendarQueue::heap_remove(std::int32_t id) {
  const auto at = static_cast<std::size_t>(node_[id].next);
  const std::int32_t last = heap_.back();
  heap_.pop_back();
  if (at == heap_.size()) return;
  heap_set(at, last);
  heap_sift(at);
}

// Moves the entry at `at` up or down to its place.
void CalendarQueue::heap_sift(std::size_t at) {
  auto less = [this](std::int32_t a, std::int32_t b) { return this->less(a, b); };
  auto place = [this](std::size_t k, std::int32_t id) { heap_set(k, id); };
  at = sift_up(heap_.data(), at, less, place);
  sift_down(heap_.data(), heap_.size(), at, less, place);
}

void CalendarQueue::peek_after_top(std::int32_t also, std::int32_t next[3]) const {
  next[0] = next[1] = next[2] = -1;
  const auto buckets = static_cast<std::int32_t>(head_.size());
  if (!cached_valid_ || cached_ < 0 || current_ >= buckets) return;
  if (sorted_) {  // the root's children (a hint: not necessarily the next two)
    int found = 0;
    for (std::size_t k = 1; k < 3 && k < heap_.size(); ++k)
      if (heap_[k] != also) next[found++] = heap_[k];
    return;
  }
  for (std::int32_t id = head_[static_cast<std::size_t>(current_)]; id >= 0; id = node_[id].next) {
    if (id == cached_ || id == also) continue;
    int k = 3;  // insertion into the sorted three
    while (k > 0 && (next[k - 1] < 0 || less(id, next[k - 1]))) --k;
    if (k == 3) continue;
    for (int m = 2; m > k; --m) next[m] = next[m - 1];
    next[k] = id;
  }
  int found = next[2] >= 0 ? 3 : next[1] >= 0 ? 2 : next[0] >= 0 ? 1 : 0;
  const std::int32_t end = std::min(buckets, current_ + 8);
  for (std::int32_t b = current_ + 1; found < 3 && b < end; ++b) {
    const std::int32_t id = head_[static_cast<std::size_t>(b)];
    if (id >= 0 && id != also) next[found++] = id;
  }
}

int CalendarQueue::walk_ahead(std::int32_t reached[2]) {
  const auto buckets = static_cast<std::int32_t>(head_.size());
  if (walk_bucket_ <= current_) {
    walk_bucket_ = current_ + 1;
    walk_link_count_ = 0;
  }
  int count = 0;
  auto reach = [&](std::int32_t id) {
    prefetch(id);
    reached[count++] = id;
    if (walk_link_count_ < 4) walk_links_[walk_link_count_++] = id;
  };
  if (walk_link_count_ > 0) {
    // (If that entry moved since, its link leads elsewhere: harmless for a hint.)
    const std::int32_t id = node_[walk_links_[0]].next;
    --walk_link_count_;
    for (int k = 0; k < walk_link_count_; ++k) walk_links_[k] = walk_links_[k + 1];
    if (id >= 0) reach(id);
  }
  // Eight buckets ahead (four is slower, docs/performance.md).
  const std::int32_t end = std::min(buckets, current_ + 9);
  for (; walk_bucket_ < end; ++walk_bucket_) {
    const std::int32_t id = head_[static_cast<std::size_t>(walk_bucket_)];
    if (id < 0) continue;
    reach(id);
    ++walk_bucket_;
    break;
  }
  return count;
}

bool CalendarQueue::consistent() const {
  std::size_t counted = overflow_.size() + heap_.size() + static_cast<std::size_t>(pending_count_);
  for (int k = 0; k < pending_count_; ++k)
    if (node_[pending_[k]].where != pending) return false;
  if (!sorted_ && !heap_.empty()) return false;
  for (std::size_t k = 0; k < heap_.size(); ++k) {
    if (node_[heap_[k]].where != in_heap || node_[heap_[k]].next != static_cast<std::int32_t>(k)) return false;
    if (k > 0 && less(heap_[k], heap_[(k - 1) / 2])) return false;
  }
  if (sorted_ && current_ < static_cast<std::int32_t>(head_.size()) && head_[static_cast<std::size_t>(current_)] >= 0)
    return false;  // a sorted bucket keeps no list
  for (std::size_t b = 0; b < head_.size(); ++b)
    for (std::int32_t id = head_[b]; id >= 0; id = node_[id].next) {
      if (node_[id].where != static_cast<std::int32_t>(b)) return false;
      if (static_cast<std::int32_t>(b) < current_) return false;  // behind the scan
      ++counted;
    }
  for (std::size_t s = 0; s < overflow_.size(); ++s)
    if (node_[overflow_[s]].where != in_overflow || node_[overflow_[s]].overflow_slot != static_cast<std::int32_t>(s))
      return false;
  return counted == size_;
}

}  // namespace shaker::md
