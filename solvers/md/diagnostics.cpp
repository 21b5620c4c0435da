// What the run loop and the checks read off the engine: positions, energies, overlaps, queue
// consistency and memory; never called between two events of a run.
#include "md/simulation.hpp"

#include <algorithm>
#include <cmath>

namespace shaker::md {

void Simulation::positions_at(double t, std::vector<Vec3>& r, std::vector<Vec3>& v) const {
  const std::size_t n = data_.particles.size();
  r.resize(n);
  v.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    state_at(data_.particles[i], t, geometry_.gravity, r[i], v[i]);
    r[i].x -= geometry_.width * std::floor(r[i].x / geometry_.width);
    r[i].y -= geometry_.depth * std::floor(r[i].y / geometry_.depth);
    if (geometry_.periodic_z) r[i].z -= geometry_.height * std::floor(r[i].z / geometry_.height);
  }
}

double Simulation::kinetic_energy(double t) const {
  double sum = 0.0;
  Vec3 r, v;
  for (const Particle& p : data_.particles) {
    state_at(p, t, geometry_.gravity, r, v);
    sum += 0.5 * dot(v, v);
  }
  return sum;
}

double Simulation::potential_energy(double t) const {
  double sum = 0.0;
  Vec3 r, v;
  for (const Particle& p : data_.particles) {
    state_at(p, t, geometry_.gravity, r, v);
    sum += geometry_.gravity * r.z;
  }
  return sum;
}

std::size_t Simulation::count_overlaps(double t, double tolerance) const {
  std::vector<Vec3> r, v;
  positions_at(t, r, v);
  return count_overlaps(r, tolerance);
}

std::size_t Simulation::count_overlaps(const std::vector<Vec3>& r, double tolerance) const {
  const double limit = (1.0 - tolerance) * (1.0 - tolerance);
  std::size_t overlaps = 0;
  for (std::size_t i = 0; i < r.size(); ++i) {
    const auto self = static_cast<std::int32_t>(i);
    cells_.for_each_neighbor(cells_.cell(self), [&](std::int32_t j, const Vec3&) {
      if (j <= self) return;
      Vec3 d = r[i] - r[static_cast<std::size_t>(j)];
      d.x -= geometry_.width * std::round(d.x / geometry_.width);
      d.y -= geometry_.depth * std::round(d.y / geometry_.depth);
      if (geometry_.periodic_z) d.z -= geometry_.height * std::round(d.z / geometry_.height);
      if (dot(d, d) < limit) ++overlaps;
    });
  }
  return overlaps;
}

bool Simulation::queue_consistent() const {
  const bool ok = use_calendar_ ? calendar_.consistent() && calendar_.size() == data_.particles.size()
                                : heap_.consistent() && heap_.size() == data_.particles.size();
  if (!ok) return false;
  for (const Event& e : data_.events)
    if (!(e.next() >= data_.time)) return false;
  return true;
}

std::size_t Simulation::bytes_per_particle() const {
  const std::size_t n = std::max<std::size_t>(1, data_.particles.size());
  const std::size_t per_particle = sizeof(Particle) + sizeof(Event) + sizeof(double) +
                                   3 * sizeof(std::int32_t) +
                                   (use_calendar_ ? calendar_.bytes_per_entry() : heap_.bytes_per_entry());
  // Grids: cell heads, and the calendar's buckets (at most two per particle).
  const std::size_t grids = cells_.head_.size() * sizeof(std::int32_t) +
                            (use_calendar_ ? 2 * n * sizeof(std::int32_t) : 0);
  return per_particle + height_counts_.bytes_per_particle() + grids / n;
}

}  // namespace shaker::md
