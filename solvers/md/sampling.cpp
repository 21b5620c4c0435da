#include "md/sampling.hpp"

#include <cmath>

#include "common/units.hpp"

namespace shaker::md {

PhaseSampler::PhaseSampler(int phases, double bin_height, double top, double box_width)
    : phases_(phases),
      bins_(static_cast<std::size_t>(std::ceil(top / bin_height))),
      bin_height_(bin_height),
      bin_volume_(box_width * box_width * bin_height),
      data_(static_cast<std::size_t>(phases) * bins_),
      first_time_(static_cast<std::size_t>(phases), 0.0),
      cycles_(static_cast<std::size_t>(phases), 0),
      scratch_(bins_) {}

void PhaseSampler::add(int k, double t, const std::vector<Vec3>& r, const std::vector<Vec3>& v) {
  for (Bin& b : scratch_) b = Bin{};
  for (std::size_t i = 0; i < r.size(); ++i) {
    const double u = std::floor(r[i].z / bin_height_);
    if (u < 0.0 || u >= static_cast<double>(bins_)) continue;
    Bin& b = scratch_[static_cast<std::size_t>(u)];
    b.count += 1.0;
    b.vx += v[i].x;
    b.vy += v[i].y;
    b.vz += v[i].z;
    b.v2 += dot(v[i], v[i]);
  }
  const auto phase = static_cast<std::size_t>(k);
  if (cycles_[phase]++ == 0) first_time_[phase] = t;
  Bin* out = &data_[phase * bins_];
  for (std::size_t j = 0; j < bins_; ++j) {
    const Bin& s = scratch_[j];
    Bin& a = out[j];
    a.count += s.count;
    a.vx += s.vx;
    a.vy += s.vy;
    a.vz += s.vz;
    a.v2 += s.v2;
    const double n = s.count / bin_volume_;
    a.n_sum += n;
    a.n_sq += n * n;
    if (s.count >= 1.0) {
      const double uz = s.vz / s.count;
      a.uz_sum += uz;
      a.uz_sq += uz * uz;
      a.uz_cycles += 1.0;
    }
    if (s.count >= 2.0) {
      const double ux = s.vx / s.count, uy = s.vy / s.count, uz = s.vz / s.count;
      const double T = (s.v2 / s.count - ux * ux - uy * uy - uz * uz) / 3.0;
      a.T_sum += T;
      a.T_sq += T * T;
      a.T_cycles += 1.0;
    }
  }
}

namespace {
/// Standard error of the mean from a sum and a sum of squares of m values (0 if m < 2).
double standard_error(double sum, double squares, double m) {
  if (m < 2.0) return 0.0;
  const double mean = sum / m;
  const double variance = std::max(0.0, (squares - m * mean * mean) / (m - 1.0));
  return std::sqrt(variance / m);
}
}  // namespace

std::vector<Profile> PhaseSampler::profiles(const ShakerKinematics& shaker) const {
  std::vector<Profile> out;
  for (int k = 0; k < phases_; ++k) {
    const auto phase = static_cast<std::size_t>(k);
    const double cycles = cycles_[phase];
    if (cycles == 0) continue;
    Profile p;
    p.time = first_time_[phase];
    p.phase = static_cast<double>(k) / phases_;
    p.plate_z = shaker.position(p.phase / shaker.f);
    p.plate_v = shaker.velocity(p.phase / shaker.f);
    p.bin_height = bin_height_;
    for (std::size_t j = 0; j < bins_; ++j) {
      const Bin& a = data_[phase * bins_ + j];
      const double n = a.count / (cycles * bin_volume_);
      double uz = 0.0, T = 0.0;
      if (a.count > 0.0) {
        const double ux = a.vx / a.count, uy = a.vy / a.count;
        uz = a.vz / a.count;
        T = std::max(0.0, (a.v2 / a.count - ux * ux - uy * uy - uz * uz) / 3.0);
      }
      p.z.push_back((static_cast<double>(j) + 0.5) * bin_height_);
      p.n.push_back(n);
      p.nu.push_back(volume_fraction(n));
      p.uz.push_back(uz);
      p.T.push_back(T);
      p.samples.push_back(a.count);
      p.n_se.push_back(standard_error(a.n_sum, a.n_sq, cycles));
      p.uz_se.push_back(standard_error(a.uz_sum, a.uz_sq, a.uz_cycles));
      p.T_se.push_back(standard_error(a.T_sum, a.T_sq, a.T_cycles));
    }
    out.push_back(std::move(p));
  }
  return out;
}

}  // namespace shaker::md
