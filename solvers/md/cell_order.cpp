// Keeping particles that are near in space near in memory, and the queue that indexes them.
#include "md/simulation.hpp"

#include <algorithm>

namespace shaker::md {

void Simulation::reset_queue(std::size_t n) {
  heap_.reset(use_calendar_ ? 0 : n);
  calendar_.reset(use_calendar_ ? n : 0);
  lookahead_ = n >= lookahead_min_particles;
  lookahead_members_ = n >= lookahead_members_min_particles;
  calendar_.set_deferred(lookahead_);
}

// Particles that are close in space are stored close in memory, so that a prediction reads
// few cache lines (the loss at large N is memory latency). The ids are renumbered in cell
// order, every list that holds ids is renumbered with them, and the queue is rebuilt.
void Simulation::sort_by_cell() {
  const std::size_t n = data_.particles.size();
  std::vector<std::int32_t> old_of_new;
  old_of_new.reserve(n);
  for (std::int32_t head : cells_.head_)
    for (std::int32_t j = head; j >= 0; j = cells_.next_[j]) old_of_new.push_back(j);
  std::vector<std::int32_t> new_of_old(n);
  for (std::size_t k = 0; k < n; ++k) new_of_old[static_cast<std::size_t>(old_of_new[k])] = static_cast<std::int32_t>(k);
  auto permute = [&](auto& values) {
    auto copy = values;
    for (std::size_t k = 0; k < n; ++k) values[k] = copy[static_cast<std::size_t>(old_of_new[k])];
  };
  permute(data_.particles);
  permute(data_.events);
  permute(data_.last_collision);
  height_counts_.renumber(old_of_new);
  for (Event& e : data_.events)
    if (e.partner >= 0) e.partner = new_of_old[static_cast<std::size_t>(e.partner)];
  std::vector<std::int32_t> cell_of(n);
  for (std::size_t k = 0; k < n; ++k) cell_of[k] = cells_.cell_[static_cast<std::size_t>(old_of_new[k])];
  std::fill(cells_.head_.begin(), cells_.head_.end(), -1);
  for (std::size_t k = n; k-- > 0;)  // backwards: each cell lists its particles in id order
    cells_.insert(static_cast<std::int32_t>(k), cell_of[k]);
  heap_.reset(use_calendar_ ? 0 : n);
  calendar_.reset(use_calendar_ ? n : 0);
  for (std::size_t k = 0; k < n; ++k) schedule(static_cast<std::int32_t>(k), data_.events[k].next());
}

}  // namespace shaker::md
