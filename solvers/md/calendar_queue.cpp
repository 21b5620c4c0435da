#include "md/calendar_queue.hpp"

#include <algorithm>
#include <cmath>

namespace shaker::md {

void CalendarQueue::reset(std::size_t n) {
  time_.assign(n, std::numeric_limits<double>::infinity());
  where_.assign(n, absent);
  next_.assign(n, -1);
  prev_.assign(n, -1);
  overflow_slot_.assign(n, -1);
  std::size_t buckets = 16;
  while (buckets < n) buckets *= 2;
  head_.assign(buckets, -1);
  overflow_.clear();
  current_ = static_cast<std::int32_t>(buckets);  // no window yet: the first pop builds one
  base_ = 0.0;
  size_ = 0;
  walk_bucket_ = 0;
  walk_id_ = -1;
  cached_valid_ = false;
}

void CalendarQueue::unlink(std::int32_t id) {
  const std::int32_t w = where_[id];
  if (w == absent) return;
  if (w == in_overflow) {
    const std::int32_t slot = overflow_slot_[id];
    const std::int32_t last = overflow_.back();
    overflow_[static_cast<std::size_t>(slot)] = last;
    overflow_slot_[last] = slot;
    overflow_.pop_back();
  } else {
    if (prev_[id] >= 0) next_[prev_[id]] = next_[id];
    else head_[static_cast<std::size_t>(w)] = next_[id];
    if (next_[id] >= 0) prev_[next_[id]] = prev_[id];
  }
  where_[id] = absent;
}

void CalendarQueue::place(std::int32_t id) {
  const double nb = static_cast<double>(head_.size());
  const double k = std::floor((time_[id] - base_) / width_);
  if (!(k < nb) || current_ >= static_cast<std::int32_t>(head_.size())) {
    where_[id] = in_overflow;
    overflow_slot_[id] = static_cast<std::int32_t>(overflow_.size());
    overflow_.push_back(id);
    return;
  }
  // Times before the current bucket (only by rounding) go into it: buckets are scanned in full.
  const auto bucket = std::max(current_, static_cast<std::int32_t>(std::max(k, 0.0)));
  where_[id] = bucket;
  prev_[id] = -1;
  next_[id] = head_[static_cast<std::size_t>(bucket)];
  if (next_[id] >= 0) prev_[next_[id]] = id;
  head_[static_cast<std::size_t>(bucket)] = id;
}

void CalendarQueue::update(std::int32_t id, double time) {
  if (where_[id] == absent) ++size_;
  unlink(id);
  time_[id] = time;
  place(id);
  if (cached_valid_) {
    if (id == cached_) cached_valid_ = false;
    else if (cached_ >= 0 && less(id, cached_)) cached_ = id;
    else if (cached_ < 0) cached_valid_ = false;
  }
}

void CalendarQueue::restart_window() {
  // All entries are in the overflow list here. New width: about two entries per bucket.
  double earliest = std::numeric_limits<double>::infinity(), sum = 0.0;
  std::size_t finite = 0;
  for (std::int32_t id : overflow_) {
    if (!std::isfinite(time_[id])) continue;
    earliest = std::min(earliest, time_[id]);
    sum += time_[id];
    ++finite;
  }
  current_ = 0;
  walk_bucket_ = 0;
  walk_id_ = -1;
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
      restart_window();
      if (current_ >= static_cast<std::int32_t>(head_.size())) return;  // only `never` left
    }
    std::int32_t best = -1;
    for (std::int32_t id = head_[static_cast<std::size_t>(current_)]; id >= 0; id = next_[id])
      if (best < 0 || less(id, best)) best = id;
    if (best >= 0) {
      cached_ = best;
      return;
    }
    ++current_;
  }
}

void CalendarQueue::peek_after_top(std::int32_t& first, std::int32_t& second) const {
  first = second = -1;
  const auto buckets = static_cast<std::int32_t>(head_.size());
  if (!cached_valid_ || cached_ < 0 || current_ >= buckets) return;
  for (std::int32_t id = head_[static_cast<std::size_t>(current_)]; id >= 0; id = next_[id]) {
    if (id == cached_) continue;
    if (first < 0 || less(id, first)) {
      second = first;
      first = id;
    } else if (second < 0 || less(id, second)) {
      second = id;
    }
  }
  const std::int32_t end = std::min(buckets, current_ + 8);
  for (std::int32_t b = current_ + 1; second < 0 && b < end; ++b) {
    const std::int32_t id = head_[static_cast<std::size_t>(b)];
    if (id < 0) continue;
    if (first < 0) first = id;
    else second = id;
  }
}

std::int32_t CalendarQueue::walk_ahead() {
  const auto buckets = static_cast<std::int32_t>(head_.size());
  if (walk_bucket_ <= current_) {
    walk_bucket_ = current_ + 1;
    walk_id_ = -1;
  }
  const std::int32_t end = std::min(buckets, current_ + 5);
  while (walk_bucket_ < end) {
    // (If walk_id_ moved since, its link leads elsewhere: harmless for a hint.)
    const std::int32_t id = walk_id_ < 0 ? head_[static_cast<std::size_t>(walk_bucket_)] : next_[walk_id_];
    if (id < 0) {
      ++walk_bucket_;
      walk_id_ = -1;
      continue;
    }
    walk_id_ = id;
    prefetch(id);
    return id;
  }
  return -1;
}

bool CalendarQueue::consistent() const {
  std::size_t counted = overflow_.size();
  for (std::size_t b = 0; b < head_.size(); ++b)
    for (std::int32_t id = head_[b]; id >= 0; id = next_[id]) {
      if (where_[id] != static_cast<std::int32_t>(b)) return false;
      if (static_cast<std::int32_t>(b) < current_) return false;  // behind the scan
      ++counted;
    }
  for (std::size_t s = 0; s < overflow_.size(); ++s)
    if (where_[overflow_[s]] != in_overflow || overflow_slot_[overflow_[s]] != static_cast<std::int32_t>(s))
      return false;
  return counted == size_;
}

}  // namespace shaker::md
