#include "md_sampling.hpp"

#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <memory>
#include <stdexcept>

#include "analysis/analysis.hpp"
#include "common/case_parameters.hpp"
#include "common/hdf5_file.hpp"
#include "common/run_loop.hpp"
#include "common/units.hpp"
#include "md/initial_states.hpp"
#include "md/protocol.hpp"
#include "md/sampling.hpp"
#include "md/simulation.hpp"

namespace shaker::convergence {
namespace {
constexpr double nan = std::numeric_limits<double>::quiet_NaN();

double sample_variance(std::span<const double> x) {
  const double m = static_cast<double>(x.size());
  double mean = 0.0;
  for (double v : x) mean += v;
  mean /= m;
  double squares = 0.0;
  for (double v : x) squares += (v - mean) * (v - mean);
  return squares / (m - 1.0);
}
}  // namespace

BlockEstimate block_estimate(std::span<const double> per_cycle, std::size_t K) {
  if (K < 2 || K > per_cycle.size())
    throw std::invalid_argument(fmt::format("block_estimate: K = {} with {} values", K,
                                            per_cycle.size()));
  BlockEstimate e;
  e.block_size = K;
  double mean_se2 = 0.0, mean_inverse_count = 0.0;
  std::vector<double> found;
  for (std::size_t b = 0; b < per_cycle.size() / K; ++b) {
    found.clear();
    for (double v : per_cycle.subspan(b * K, K))
      if (std::isnan(v)) ++e.missing;
      else found.push_back(v);
    if (found.size() < 2) continue;
    const double n = static_cast<double>(found.size());
    mean_se2 += sample_variance(found) / n;
    mean_inverse_count += 1.0 / n;
    ++e.blocks;
    e.degrees_of_freedom += found.size() - 1;
  }
  if (e.blocks == 0) {
    e.standard_error = nan;
    return e;
  }
  const double blocks = static_cast<double>(e.blocks);
  e.standard_error = std::sqrt(mean_se2 / blocks);
  e.effective_count = blocks / mean_inverse_count;
  return e;
}

double block_standard_error(std::span<const double> per_cycle, std::size_t K) {
  const BlockEstimate e = block_estimate(per_cycle, K);
  if (e.missing) throw std::invalid_argument("block_standard_error: a value is NaN");
  return e.standard_error;
}

BlockEstimate complete_blocks(std::size_t cycles, std::size_t K, double standard_error) {
  BlockEstimate e;
  e.block_size = K;
  e.standard_error = standard_error;
  e.effective_count = static_cast<double>(K);
  e.blocks = K ? cycles / K : 0;
  e.degrees_of_freedom = e.blocks * (K - 1);
  return e;
}

double expected_slope_scatter(std::span<const BlockEstimate> estimates) {
  const double m = static_cast<double>(estimates.size());
  double mean_x = 0.0;
  for (const auto& e : estimates) mean_x += std::log(e.effective_count) / m;
  double sxx = 0.0, weighted = 0.0;
  for (const auto& e : estimates) {
    const double dx = std::log(e.effective_count) - mean_x;
    sxx += dx * dx;
    weighted += dx * dx / (2.0 * static_cast<double>(e.degrees_of_freedom));
  }
  return std::sqrt(weighted) / sxx;
}

double expected_slope_scatter(std::span<const std::size_t> block_sizes, std::size_t cycles) {
  std::vector<BlockEstimate> estimates;
  for (std::size_t K : block_sizes) estimates.push_back(complete_blocks(cycles, K, 1.0));
  return expected_slope_scatter(estimates);
}

bool SamplingFit::pass() const {
  return std::isfinite(fit.order) && std::abs(fit.order - expected_slope) <= band;
}

SamplingFit fit_sampling(const std::string& study, const std::string& quantity, double phase,
                         std::vector<BlockEstimate> estimates) {
  SamplingFit f;
  f.study = study;
  f.quantity = quantity;
  f.phase = phase;
  f.estimates = std::move(estimates);
  std::vector<double> K, se;
  bool usable = true;
  for (const auto& e : f.estimates) {
    K.push_back(e.effective_count);
    se.push_back(e.standard_error);
    usable = usable && e.standard_error > 0.0 && std::isfinite(e.standard_error) &&
             e.degrees_of_freedom > 0;
  }
  if (!usable) {  // a zero or missing se fails the check
    f.fit = OrderFit{nan, nan, nan, K.size()};
    f.band = nan;
    return f;
  }
  f.band = slope_band_sigmas * expected_slope_scatter(f.estimates);
  f.fit = fit_order(K, se);
  return f;
}

std::vector<std::size_t> layer_bins(const Profile& p) {
  std::vector<std::size_t> bins;
  for (std::size_t i = 0; i < p.size(); ++i)
    if (p.nu[i] > analysis::layer_volume_fraction) bins.push_back(i);
  return bins;
}

Profile pair_average(const Profile& fine) {
  Profile p = fine;
  p.bin_height = 2.0 * fine.bin_height;
  const std::size_t bins = fine.size() / 2;
  auto mean = [](const std::vector<double>& x, std::size_t j) { return 0.5 * (x[2 * j] + x[2 * j + 1]); };
  auto combined = [](const std::vector<double>& se, std::size_t j) {
    return 0.5 * std::hypot(se[2 * j], se[2 * j + 1]);
  };
  for (auto* field : {&p.z, &p.n, &p.nu, &p.uz, &p.T, &p.samples, &p.n_se, &p.uz_se, &p.T_se})
    field->assign(bins, 0.0);
  for (std::size_t j = 0; j < bins; ++j) {
    p.z[j] = mean(fine.z, j);
    p.n[j] = mean(fine.n, j);
    p.nu[j] = mean(fine.nu, j);
    p.uz[j] = mean(fine.uz, j);
    p.T[j] = mean(fine.T, j);
    p.samples[j] = fine.samples[2 * j] + fine.samples[2 * j + 1];
    p.n_se[j] = combined(fine.n_se, j);
    p.uz_se[j] = combined(fine.uz_se, j);
    p.T_se[j] = combined(fine.T_se, j);
  }
  return p;
}

FieldAgreement compare_fields(const Profile& coarse, const Profile& paired, const std::string& field,
                              double sigmas) {
  if (coarse.size() != paired.size())
    throw std::invalid_argument(fmt::format("compare_fields: {} bins against {}", coarse.size(),
                                            paired.size()));
  const auto value = field == "T" ? &Profile::T : field == "uz" ? &Profile::uz
                     : field == "nu" ? &Profile::nu
                                     : throw std::invalid_argument("compare_fields: field " + field);
  const auto se = field == "T" ? &Profile::T_se : field == "uz" ? &Profile::uz_se : &Profile::n_se;
  const double se_scale = field == "nu" ? volume_fraction(1.0) : 1.0;
  FieldAgreement a;
  for (std::size_t i : layer_bins(coarse)) {
    const double difference = std::abs((coarse.*value)[i] - (paired.*value)[i]);
    const double combined = se_scale * std::hypot((coarse.*se)[i], (paired.*se)[i]);
    ++a.bins;
    if (difference < sigmas * combined) ++a.within;
    a.max_abs_difference = std::max(a.max_abs_difference, difference);
    if (difference / combined > a.max_difference_in_se) {
      a.max_difference_in_se = difference / combined;
      a.worst_z = coarse.z[i];
    }
  }
  return a;
}

bool BinSizeCheck::pass() const {
  if (!std::isfinite(value) || !std::isfinite(limit)) return false;
  return criterion == "at_least" ? value >= limit : value <= limit;
}

// ---- the trajectory ---------------------------------------------------------------------

const Profile& at_phase(const std::vector<Profile>& profiles, double phase) {
  const auto phases = static_cast<double>(profiles.size());
  const auto k = static_cast<std::size_t>(std::lround(phase * phases));
  if (profiles.empty() || k >= profiles.size() || std::abs(profiles[k].phase - phase) > 1e-9)
    throw std::invalid_argument(fmt::format("f t = {} is not on the grid of {} phases", phase,
                                            profiles.size()));
  return profiles[k];
}

namespace {

md::Simulation make_simulation(const CaseParameters& c, const md::MdSettings& s) {
  md::Geometry g;
  g.width = c.md_box_width;
  g.depth = c.md_box_depth;
  g.height = s.ceiling;
  g.gravity = gravity;
  g.plate = c.shaker;
  md::CollisionRules rules;
  rules.restitution = c.restitution;
  rules.tc_guard = s.tc_guard;
  rules.tc = s.tc;
  return md::Simulation(g, rules, md::flat_layer(g, static_cast<std::size_t>(c.particles), c.run.seed),
                        s.queue);
}

/// A single-cycle profile has no spread to give standard errors (NaN): drop them, so that the
/// shock detection sees them as not stored.
Profile without_standard_errors(Profile p) {
  p.n_se.clear();
  p.uz_se.clear();
  p.T_se.clear();
  return p;
}

double shock_location(const Profile& p) {
  const auto shock = analysis::find_shock(p);
  return shock ? shock->location : nan;
}

/// The study's samplers, fed the particles at every stored phase of the sampled cycles; each
/// cycle's quantities and each block's standard errors taken at the cycle's end.
class StudySampling final : public RunObserver {
 public:
  StudySampling(const CaseParameters& c, const md::MdSettings& s, const md::Simulation& sim,
                std::span<const std::size_t> block_sizes, double fine_bin_height, SamplingTrajectory& out)
      : c_(c), bin_(s.bin_height), fine_bin_(fine_bin_height), top_(s.ceiling), block_sizes_(block_sizes),
        snapshot_(sim), out_(out), pooled_(sampler(bin_)), pooled_fine_(sampler(fine_bin_)),
        cycle_(sampler(bin_)), cycle_fine_(sampler(fine_bin_)) {
    for (std::size_t b = 0; b < block_sizes.size(); ++b) blocks_.push_back(sampler(bin_));
  }

  void at_phase(const PhaseInstant& instant) override {
    if (!instant.sampled) return;
    snapshot_.take(instant.t);
    const auto k = static_cast<int>(instant.phase);
    for (auto* one : {pooled_.get(), pooled_fine_.get(), cycle_.get(), cycle_fine_.get()})
      one->add(k, instant.t, snapshot_.r(), snapshot_.v());
    for (auto& block : blocks_) block->add(k, instant.t, snapshot_.r(), snapshot_.v());
  }

  void at_cycle_end(const CycleEnd& end) override {
    if (!end.sampled) return;
    record_quantities();
    const auto done = static_cast<std::size_t>(end.cycle + 1 - c_.run.transient_cycles);
    for (std::size_t b = 0; b < block_sizes_.size(); ++b)
      if (done % block_sizes_[b] == 0) close_block(b, done);
    cycle_ = sampler(bin_);
    cycle_fine_ = sampler(fine_bin_);
  }

  void finish() {
    out_.pooled = pooled_->profiles(c_.shaker);
    out_.pooled_fine = pooled_fine_->profiles(c_.shaker);
  }

 private:
  std::unique_ptr<md::PhaseSampler> sampler(double bin) const {
    return std::make_unique<md::PhaseSampler>(static_cast<int>(c_.run.phases_per_cycle), bin, top_,
                                              c_.md_box_width * c_.md_box_depth);
  }

  void record_quantities() {
    const std::vector<Profile> profiles = cycle_->profiles(c_.shaker);
    for (std::size_t q = 0; q < out_.quantity_names.size(); ++q) {
      const Profile p = without_standard_errors(convergence::at_phase(profiles, out_.quantity_phases[q]));
      out_.per_cycle[q].push_back(out_.quantity_names[q] == "shock_location" ? shock_location(p)
                                                                            : analysis::center_of_mass(p));
    }
    out_.per_cycle_shock_fine.push_back(
        shock_location(without_standard_errors(convergence::at_phase(cycle_fine_->profiles(c_.shaker), 0.22))));
  }

  void close_block(std::size_t b, std::size_t done) {
    const std::vector<Profile> block = blocks_[b]->profiles(c_.shaker);
    if (b == 0 && done == block_sizes_[0]) out_.first_block = block;
    auto& n_se = out_.n_se[b].emplace_back();
    auto& T_se = out_.T_se[b].emplace_back();
    for (const Profile& p : block) {
      n_se.push_back(p.n_se);
      T_se.push_back(p.T_se);
    }
    blocks_[b] = sampler(bin_);
  }

  const CaseParameters& c_;
  double bin_, fine_bin_, top_;
  std::span<const std::size_t> block_sizes_;
  md::PhaseSnapshot snapshot_;
  SamplingTrajectory& out_;
  std::unique_ptr<md::PhaseSampler> pooled_, pooled_fine_, cycle_, cycle_fine_;
  std::vector<std::unique_ptr<md::PhaseSampler>> blocks_;
};

}  // namespace

SamplingTrajectory run_sampling_trajectory(const config::Config& config,
                                           std::span<const std::size_t> block_sizes,
                                           double fine_bin_height) {
  const CaseParameters c = CaseParameters::from(config);
  const md::MdSettings s = md::MdSettings::from(config);
  if (c.run.kind != RunProtocol::Kind::periodic)
    throw std::invalid_argument("run_sampling_trajectory: needs run.protocol = periodic");
  const auto cycles = static_cast<std::size_t>(c.run.sampled_cycles);
  for (std::size_t K : block_sizes)
    if (K < 2 || cycles % K != 0)
      throw std::invalid_argument(fmt::format("block size {} does not divide {} cycles", K, cycles));

  SamplingTrajectory out;
  out.cycles = cycles;
  out.quantity_names = {"center_of_mass", "center_of_mass", "center_of_mass", "center_of_mass",
                        "shock_location"};
  out.quantity_phases = {0.0, 0.25, 0.5, 0.75, 0.22};
  out.per_cycle.assign(out.quantity_names.size(), {});
  out.n_se.resize(block_sizes.size());
  out.T_se.resize(block_sizes.size());

  md::Simulation sim = make_simulation(c, s);
  StudySampling sampling(c, s, sim, block_sizes, fine_bin_height, out);
  const auto start = std::chrono::steady_clock::now();
  md::DrivenSimulation driven(sim);
  PhaseSchedule::whole_cycles(c.run, c.shaker, sim.time()).run(driven, {&sampling});
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  sampling.finish();
  return out;
}

double layer_rms_standard_error(const std::vector<std::vector<std::vector<double>>>& blocks_se,
                                const std::vector<Profile>& pooled, double phase) {
  double sum = 0.0;
  std::size_t count = 0;
  for (std::size_t k = 0; k < pooled.size(); ++k) {
    if (phase >= 0.0 && &pooled[k] != &at_phase(pooled, phase)) continue;
    for (std::size_t i : layer_bins(pooled[k]))
      for (const auto& block : blocks_se) {
        sum += block[k][i] * block[k][i];
        ++count;
      }
  }
  return count ? std::sqrt(sum / static_cast<double>(count)) : nan;
}

// ---- tables -----------------------------------------------------------------------------

namespace {
std::string number(double x) { return fmt::format("{:.17g}", x); }
std::string phase_text(double phase) { return std::isnan(phase) ? "nan" : number(phase); }
}  // namespace

std::vector<std::filesystem::path> write_sampling_study(const std::filesystem::path& directory,
                                                        const std::string& name,
                                                        std::span<const SamplingFit> fits,
                                                        std::span<const BinSizeCheck> bin_checks) {
  if (name.find_first_of("/,\"\n") != std::string::npos)
    throw std::invalid_argument("write_sampling_study: bad study file name " + name);
  std::string se = "study,quantity,phase,K,blocks,degrees_of_freedom,effective_K,missing,"
                   "standard_error\n";
  std::string fit = "study,quantity,phase,fit_points,fitted_slope,slope_std_error,expected_slope,"
                    "band,pass\n";
  for (const SamplingFit& f : fits) {
    for (const BlockEstimate& e : f.estimates)
      se += fmt::format("{},{},{},{},{},{},{},{},{}\n", f.study, f.quantity, phase_text(f.phase),
                        e.block_size, e.blocks, e.degrees_of_freedom, number(e.effective_count),
                        e.missing, number(e.standard_error));
    fit += fmt::format("{},{},{},{},{},{},{},{},{}\n", f.study, f.quantity, phase_text(f.phase),
                       f.fit.points, number(f.fit.order), number(f.fit.order_std_error),
                       number(f.expected_slope), number(f.band), f.pass() ? 1 : 0);
  }
  std::string bins = "study,quantity,phase,sigma_value,half_sigma_value,statistic,value,criterion,"
                     "limit,pass\n";
  for (const BinSizeCheck& b : bin_checks)
    bins += fmt::format("{},{},{},{},{},{},{},{},{},{}\n", b.study, b.quantity, phase_text(b.phase),
                        number(b.sigma_value), number(b.half_sigma_value), b.statistic,
                        number(b.value), b.criterion, number(b.limit), b.pass() ? 1 : 0);

  return write_study_files(directory, name, {{".sampling.csv", se}, {".sampling-fit.csv", fit},
                                             {".bin-size.csv", bins}});
}

}  // namespace shaker::convergence
