#include "md/sampling.hpp"

#include <cmath>
#include <utility>

namespace shaker::md {

PhaseSampler::PhaseSampler(int phases, double bin_height, double top, double box_area)
    : phases_(phases),
      bins_(static_cast<std::size_t>(std::ceil(top / bin_height))),
      bin_height_(bin_height),
      samples_(static_cast<std::size_t>(phases), bins_, box_area * bin_height),
      first_time_(static_cast<std::size_t>(phases), 0.0),
      cycles_(static_cast<std::size_t>(phases), 0),
      scratch_(bins_) {}

void PhaseSampler::add(int k, double t, const std::vector<Vec3>& r, const std::vector<Vec3>& v) {
  for (BinSums& b : scratch_) b = BinSums{};
  for (std::size_t i = 0; i < r.size(); ++i) {
    const double u = std::floor(r[i].z / bin_height_);
    if (u < 0.0 || u >= static_cast<double>(bins_)) continue;
    BinSums& b = scratch_[static_cast<std::size_t>(u)];
    b.count += 1.0;
    b.vx += v[i].x;
    b.vy += v[i].y;
    b.vz += v[i].z;
    b.v2 += dot(v[i], v[i]);
  }
  const auto phase = static_cast<std::size_t>(k);
  if (cycles_[phase]++ == 0) first_time_[phase] = t;
  samples_.add_cycle(phase, scratch_);
}

std::vector<Profile> PhaseSampler::profiles(const ShakerKinematics& shaker) const {
  std::vector<Profile> out;
  for (int k = 0; k < phases_; ++k) {
    const auto phase = static_cast<std::size_t>(k);
    if (cycles_[phase] == 0) continue;
    Profile p;
    p.time = first_time_[phase];
    p.phase = static_cast<double>(k) / phases_;
    p.plate_z = shaker.position(p.phase / shaker.frequency());
    p.plate_v = shaker.velocity(p.phase / shaker.frequency());
    p.bin_height = bin_height_;
    for (std::size_t j = 0; j < bins_; ++j) p.z.push_back((static_cast<double>(j) + 0.5) * bin_height_);
    samples_.pool(phase, p);
    out.push_back(std::move(p));
  }
  return out;
}

CycleSamples PhaseSampler::samples() const {
  std::vector<std::vector<double>> cycles;
  std::vector<std::vector<BinSums>> sums;
  for (std::size_t k = 0; k < static_cast<std::size_t>(phases_); ++k)
    if (cycles_[k] > 0) {
      cycles.push_back(samples_.cycles(k));
      sums.push_back(samples_.sums(k));
    }
  return CycleSamples::from_arrays(bins_, samples_.bin_volume(), std::move(cycles), std::move(sums));
}

void PhaseSampler::resume(CycleSamples saved, const std::vector<double>& first_times) {
  for (std::size_t k = 0; k < saved.phases(); ++k) {
    double cycles = 0.0;
    for (double c : saved.cycles(k)) cycles += c;
    cycles_[k] = static_cast<int>(cycles);
    first_time_[k] = first_times[k];
  }
  samples_ = std::move(saved);
}

void PhaseSnapshot::take(double t) {
  if (t == t_) return;
  simulation_.positions_at(t, r_, v_);
  t_ = t;
}

void SamplingObserver::at_phase(const PhaseInstant& instant) {
  if (!instant.sampled) return;
  snapshot_.take(instant.t);
  sampler_.add(static_cast<int>(instant.phase), instant.t, snapshot_.r(), snapshot_.v());
}

}  // namespace shaker::md
