#include "app/commands.hpp"

#include <fmt/format.h>

#include <cmath>

#include "analysis/analysis.hpp"
#include "common/config.hpp"
#include "common/describe.hpp"
#include "common/hdf5_file.hpp"
#include "common/run_file.hpp"
#include "continuum/run_continuum.hpp"
#include "md/run_md.hpp"

namespace shaker {
namespace {

config::Config load(const RunOptions& options) {
  return config::Config::load(options.config_file, options.overrides);
}

std::string optional_number(const std::optional<double>& x, int precision = 3) {
  return x ? fmt::format("{:.{}f}", *x, precision) : std::string("-");
}

}  // namespace

CLI::App* add_run_subcommand(CLI::App& app, const std::string& name, const std::string& help,
                             RunOptions& options) {
  auto* sub = app.add_subcommand(name, help);
  sub->add_option("CONFIG", options.config_file, "case file (TOML)")->required();
  sub->add_option("--set", options.overrides,
                  "override a configuration key, e.g. --set material.e=0.8 (repeatable)")
      ->type_name("KEY=VALUE")
      ->allow_extra_args(false);
  return sub;
}

int command_md(const RunOptions& options) { return md::run(load(options)); }
int command_continuum(const RunOptions& options) { return continuum::run(load(options)); }

int command_config(const RunOptions& options) {
  fmt::print("{}", config::annotate_units(load(options).to_toml()));
  return 0;
}

int command_describe(bool markdown) {
  fmt::print("{}", config::describe_schema(markdown));
  return 0;
}

namespace {
// One row per stored phase and bin: the profile and its Mach number (for plots of Ma(z)).
void write_profiles_csv(const RunRecord& run, const std::string& path) {
  std::string csv = "phase,z,n,nu,uz,T,mach\n";
  for (const auto& p : run.profiles) {
    const auto mach = analysis::mach_number(p, run.e);
    for (std::size_t i = 0; i < p.size(); ++i)
      csv += fmt::format("{},{},{},{},{},{},{}\n", p.phase, p.z[i], p.n[i], p.nu[i], p.uz[i],
                         p.T[i], mach[i]);
  }
  write_text_atomically(path, csv);
}
}  // namespace

int command_analyze(const std::string& run_file, const std::string& csv_file,
                    const std::string& profiles_csv) {
  const RunRecord run = read_run_file(run_file);
  fmt::print("# {}: solver {}, {}, e = {}, program {} ({})\n", run_file, run.solver,
             run.model_variant, run.e, run.program_version, run.git_commit);
  fmt::print("{:>7} {:>8} {:>8} {:>8} {:>8} {:>8} {:>7} {:>7} {:>7}\n", "phase", "plate_z",
             "layer_lo", "layer_hi", "com", "shock_z", "width", "d/xi", "max_Ma");
  std::string csv = "phase,time,plate_z,layer_bottom,layer_top,center_of_mass,shock_location,"
                    "shock_width,width_over_mfp,max_mach,shock_compressed_top,"
                    "shock_undisturbed_bottom\n";
  auto field = [](bool present, double value) {
    return present ? fmt::format("{}", value) : std::string("nan");
  };
  for (const auto& p : run.profiles) {
    const auto s = analysis::summarize(p, run.e);
    const auto layer = s.layer.value_or(analysis::Layer{});
    const auto shock = s.shock.value_or(analysis::Shock{});
    const bool l = s.layer.has_value(), k = s.shock.has_value();
    fmt::print("{:7.4f} {:8.3f} {:>8} {:>8} {:8.3f} {:>8} {:>7} {:>7} {:7.2f}\n", s.phase,
               s.plate_z, optional_number(l ? std::optional(layer.bottom) : std::nullopt),
               optional_number(l ? std::optional(layer.top) : std::nullopt), s.center_of_mass,
               optional_number(k ? std::optional(shock.location) : std::nullopt),
               optional_number(k ? std::optional(shock.width) : std::nullopt, 2),
               optional_number(k ? std::optional(shock.width_over_mfp()) : std::nullopt, 2),
               s.max_mach);
    csv += fmt::format("{},{},{},{},{},{},{},{},{},{},{},{}\n", s.phase, p.time, s.plate_z,
                       field(l, layer.bottom), field(l, layer.top), s.center_of_mass,
                       field(k, shock.location), field(k, shock.width),
                       field(k, k ? shock.width_over_mfp() : 0.0), s.max_mach,
                       field(k, shock.compressed_top), field(k, shock.undisturbed_bottom));
  }
  const auto speed = analysis::shock_speed(run.profiles);
  fmt::print("# average shock speed (plate frame): {}\n", optional_number(speed));
  if (!csv_file.empty()) write_text_atomically(csv_file, csv);
  if (!profiles_csv.empty()) write_profiles_csv(run, profiles_csv);
  return 0;
}

int command_compare(const std::string& first, const std::string& second,
                    const std::string& csv_file) {
  const RunRecord a = read_run_file(first), b = read_run_file(second);
  const auto r = analysis::compare_runs(a, b);
  fmt::print("# A = {} ({}), B = {} ({}, reference)\n", first, a.solver, second, b.solver);
  fmt::print("shock location: fractional RMS {:.4f}, absolute RMS {:.3f} sigma over {} phases\n",
             r.shock_location.fractional_rms, r.shock_location.absolute_rms,
             r.shock_location.count);
  fmt::print("centre of mass: fractional RMS {:.4f}, absolute RMS {:.3f} sigma over {} phases\n",
             r.center_of_mass.fractional_rms, r.center_of_mass.absolute_rms,
             r.center_of_mass.count);
  fmt::print("{:>7} {:>9} {:>9} {:>9} {:>9} {:>9} {:>9}\n", "phase", "nu_L1", "nu_L2", "nu_max",
             "T_L1", "T_L2", "T_max");
  for (std::size_t k = 0; k < r.phases.size(); ++k)
    fmt::print("{:7.4f} {:9.4f} {:9.4f} {:9.4f} {:9.4f} {:9.4f} {:9.4f}\n", r.phases[k],
               r.nu_norms[k].l1, r.nu_norms[k].l2, r.nu_norms[k].linf, r.T_norms[k].l1,
               r.T_norms[k].l2, r.T_norms[k].linf);
  if (!csv_file.empty()) {
    std::string csv = "metric,value\n";
    auto row = [&](const char* name, double value) { csv += fmt::format("{},{}\n", name, value); };
    row("shock_location_fractional_rms", r.shock_location.fractional_rms);
    row("shock_location_absolute_rms", r.shock_location.absolute_rms);
    row("shock_location_phases", static_cast<double>(r.shock_location.count));
    row("center_of_mass_fractional_rms", r.center_of_mass.fractional_rms);
    row("center_of_mass_absolute_rms", r.center_of_mass.absolute_rms);
    row("center_of_mass_phases", static_cast<double>(r.center_of_mass.count));
    double nu_l1 = 0.0, T_l1 = 0.0, nu_max = 0.0, T_max = 0.0;
    for (std::size_t k = 0; k < r.phases.size(); ++k) {
      nu_l1 += r.nu_norms[k].l1 / static_cast<double>(r.phases.size());
      T_l1 += r.T_norms[k].l1 / static_cast<double>(r.phases.size());
      nu_max = std::max(nu_max, r.nu_norms[k].linf);
      T_max = std::max(T_max, r.T_norms[k].linf);
    }
    row("nu_l1_mean_over_phases", nu_l1);
    row("nu_linf_max_over_phases", nu_max);
    row("T_l1_mean_over_phases", T_l1);
    row("T_linf_max_over_phases", T_max);
    write_text_atomically(csv_file, csv);
  }
  return 0;
}

}  // namespace shaker
