// `shaker analyze --patterns`: the pattern quantities of docs/analysis.md ("Patterns") for
// every frame of an MD run's particle file or every snapshot of a 3D continuum run's fields
// file, and their means over cycles per stored phase.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <utility>
#include <optional>

#include "analysis/pattern.hpp"
#include "app/commands.hpp"
#include "common/errors.hpp"
#include "common/atomic_output.hpp"
#include "common/hdf5_file.hpp"
#include "common/run_file.hpp"
#include "continuum/output.hpp"
#include "md/particle_file.hpp"

namespace shaker {
namespace {

/// The two fields of a frame, and where the frame sits in the run.
struct FramePatterns {
  std::int64_t cycle = 0;
  double phase = 0.0, time = 0.0;
  analysis::HorizontalField mass, height;
  analysis::PatternMeasure mass_measure, height_measure;
};

/// observables/<name>/value of the particle file, one value per frame.
std::vector<double> per_frame(const std::filesystem::path& path, const std::string& name,
                              std::int64_t frames, const std::string& source) {
  const std::string dataset = "observables/" + name + "/value";
  std::vector<double> values;
  try {
    const h5::Handle file = h5::open_file(path);
    values = h5::read_doubles(file.id(), dataset);
  } catch (const std::runtime_error& error) {
    throw InputError(fmt::format("{}: {} is unreadable: {}", source, dataset, error.what()));
  }
  if (static_cast<std::int64_t>(values.size()) != frames)
    throw InputError(fmt::format("{}: {} holds {} values for {} frames; allowed: one per frame", source,
                                 dataset, values.size(), frames));
  return values;
}

analysis::HorizontalGrid pattern_grid(const double edges[3], double cell, const std::string& source) {
  const double cells_x = std::round(edges[0] / cell), cells_y = std::round(edges[1] / cell);
  if (cells_x < 2.0 || cells_y < 2.0)
    throw InputError(fmt::format("--pattern-cell = {} gives {} x {} cells across the box {} x {} sigma "
                                 "of {}; allowed: at most half the box width", cell, cells_x, cells_y,
                                 edges[0], edges[1], source));
  return {static_cast<std::size_t>(cells_x), static_cast<std::size_t>(cells_y), edges[0], edges[1]};
}

/// Both measures of a frame; InputError names the file and frame of a field that has none.
void measure(FramePatterns& frame, const std::string& source, std::size_t f) {
  try {
    frame.mass_measure = analysis::measure_pattern(frame.mass);
    frame.height_measure = analysis::measure_pattern(frame.height);
  } catch (const InputError& error) {
    throw InputError(fmt::format("{}, frame {}: {}", source, f, error.what()));
  }
}

/// A fields file's snapshots: each snapshot's density summed over the columns of the fields'
/// own cells, its bottom the plate.
std::vector<FramePatterns> field_frame_patterns(const std::filesystem::path& path) {
  const std::string source = fmt::format("fields file '{}'", path.string());
  try {
    const h5::Handle file = h5::open_file(path);
    const double h = h5::read_double_attribute(file.id(), "cell_size");
    const std::int64_t nx = h5::read_integer_attribute(file.id(), "nx"),
                       ny = h5::read_integer_attribute(file.id(), "ny"),
                       nz = h5::read_integer_attribute(file.id(), "nz");
    if (!(h > 0.0) || nx < 2 || ny < 2 || nz < 1)
      throw InputError(fmt::format("{}: cell_size {} and {} x {} x {} cells; allowed: cell_size > 0, "
                                   "nx and ny >= 2, nz >= 1", source, h, nx, ny, nz));
    const auto [x, y] = std::pair{static_cast<std::size_t>(nx), static_cast<std::size_t>(ny)};
    const analysis::HorizontalGrid grid{x, y, static_cast<double>(nx) * h, static_cast<double>(ny) * h};
    std::vector<FramePatterns> out;
    for (std::size_t s = 0; h5::exists(file.id(), continuum::fields_snapshot_group(s)); ++s) {
      const h5::Handle group = h5::open_group(file.id(), continuum::fields_snapshot_group(s));
      const analysis::DensityColumns density{grid, static_cast<std::size_t>(nz),
                                             h5::read_double_attribute(group.id(), "plate_z"), h,
                                             h5::read_doubles(group.id(), "n")};
      if (density.n.size() != grid.cells() * density.nz)
        throw InputError(fmt::format("{}: {}/n holds {} values; allowed: nx ny nz = {}", source,
                                     continuum::fields_snapshot_group(s), density.n.size(),
                                     grid.cells() * density.nz));
      FramePatterns fp{h5::read_integer_attribute(group.id(), "cycle"),
                       h5::read_double_attribute(group.id(), "phase"),
                       h5::read_double_attribute(group.id(), "time"), analysis::column_mass_field(density),
                       analysis::center_of_mass_height_field(density), {}, {}};
      measure(fp, source, s);
      out.push_back(std::move(fp));
    }
    if (out.empty()) throw InputError(fmt::format("{}: no group snapshot_000; not a fields file", source));
    return out;
  } catch (const InputError&) {
    throw;
  } catch (const std::runtime_error& error) {
    throw InputError(fmt::format("{} is unreadable: {}", source, error.what()));
  }
}

std::vector<FramePatterns> particle_frame_patterns(const std::filesystem::path& path, double cell) {
  const std::string source = fmt::format("particle file '{}'", path.string());
  const std::int64_t frames = md::read_particle_frame(path, 0, source).frames;
  const std::vector<double> phases = per_frame(path, "phase", frames, source);
  const std::vector<double> cycles = per_frame(path, "cycle", frames, source);
  std::vector<FramePatterns> out;
  for (std::int64_t f = 0; f < frames; ++f) {
    const md::StoredFrame stored = md::read_particle_frame(path, f, source);
    const analysis::HorizontalGrid grid = pattern_grid(stored.edges, cell, source);
    analysis::ParticlePositions p;
    for (const auto& r : stored.frame.r) p.x.push_back(r.x), p.y.push_back(r.y), p.z.push_back(r.z);
    FramePatterns fp{static_cast<std::int64_t>(cycles[f]), phases[f], stored.frame.time,
                     analysis::column_mass_field(p, grid), analysis::center_of_mass_height_field(p, grid),
                     {}, {}};
    measure(fp, source, static_cast<std::size_t>(f));
    out.push_back(std::move(fp));
  }
  return out;
}

/// Phases stored as k / K to round-off (a continuum snapshot's f t from its time) are one phase.
bool same_phase(double a, double b) { return std::abs(a - b) < 1e-9; }

/// The frame at the same phase one cycle earlier, if the file holds it.
std::optional<std::size_t> previous_cycle(const std::vector<FramePatterns>& frames, std::size_t f) {
  for (std::size_t g = 0; g < frames.size(); ++g)
    if (frames[g].cycle + 1 == frames[f].cycle && same_phase(frames[g].phase, frames[f].phase)) return g;
  return std::nullopt;
}

/// A frame's correlations with the same phase one cycle earlier (NaN without that frame).
struct Correlations {
  double plain = NAN, half_wavelength = NAN;
};

Correlations correlations(const std::optional<std::size_t>& before, const std::vector<FramePatterns>& frames,
                          analysis::HorizontalField FramePatterns::*field, std::size_t f) {
  if (!before) return {};
  const analysis::HorizontalField &a = frames[*before].*field, &b = frames[f].*field;
  return {analysis::field_correlation(a, b), analysis::half_wavelength_correlation(a, b)};
}

std::string measure_columns(const analysis::PatternMeasure& m, const Correlations& c) {
  return fmt::format("{},{},{},{},{},{},{},{},{}", m.dominant.k, m.dominant.wavelength, m.symmetry.a2,
                     m.symmetry.a4, m.symmetry.a6, analysis::to_string(m.symmetry.symmetry),
                     m.order_parameter, c.plain, c.half_wavelength);
}

/// "# patterns at phase P, FIELD over N cycles: ..." for one stored phase and field.
std::string summary_line(double phase, const char* field, const char* unit,
                         const std::vector<analysis::PatternMeasure>& measures,
                         const std::vector<Correlations>& pairs) {
  const analysis::PatternSummary s = analysis::summarize_patterns(measures);
  std::vector<double> plain, shifted;
  for (const Correlations& pair : pairs) plain.push_back(pair.plain), shifted.push_back(pair.half_wavelength);
  const analysis::MeanAndError c = analysis::mean_and_error(plain), h = analysis::mean_and_error(shifted);
  const auto e = [](const analysis::MeanAndError& m) {
    return fmt::format("{:.4g} ({:.2g})", m.mean, m.standard_error);
  };
  return fmt::format("# patterns at phase {}, {} over {} frame(s): k* {} 1/sigma, wavelength {} sigma, "
                     "A2 {}, A4 {}, A6 {} ({}), order parameter {} {}, cycle-to-cycle correlation {} "
                     "(half-wavelength shifted {}) over {} pair(s)\n", phase, field, measures.size(), e(s.k),
                     e(s.wavelength), e(s.a2), e(s.a4), e(s.a6),
                     analysis::to_string(analysis::classify_symmetry(s.a2.mean, s.a4.mean, s.a6.mean,
                                                                     analysis::SymmetryOptions{}.threshold)),
                     e(s.order_parameter), unit, e(c), e(h), c.samples);
}

}  // namespace

std::filesystem::path pattern_snapshots_path(const std::filesystem::path& run_file) {
  const std::filesystem::path particles = md::particle_h5_path(run_file);
  const std::filesystem::path fields = derived_name(run_file, ".fields.h5");
  return !std::filesystem::exists(particles) && std::filesystem::exists(fields) ? fields : particles;
}

PatternTables pattern_tables(const std::filesystem::path& snapshots, double cell) {
  std::string kind;
  try {
    const h5::Handle file = h5::open_file(snapshots);
    if (h5::has_attribute(file.id(), file_kind_attribute))
      kind = h5::read_string_attribute(file.id(), file_kind_attribute);
  } catch (const std::runtime_error& error) {
    throw InputError(fmt::format("snapshot file '{}' is unreadable: {}; --patterns reads RUN.particles.h5 "
                                 "(shaker md with md.snapshot_phases) or RUN.fields.h5 (a 3D shaker "
                                 "continuum with continuum.field_phases)", snapshots.string(), error.what()));
  }
  if (kind != md::particle_file_kind && kind != continuum::fields_file_kind)
    throw InputError(fmt::format("'{}' has kind '{}' (root attribute {}); allowed: '{}' or '{}'",
                                 snapshots.string(), kind, file_kind_attribute, md::particle_file_kind,
                                 continuum::fields_file_kind));
  const std::vector<FramePatterns> frames = kind == md::particle_file_kind
                                                ? particle_frame_patterns(snapshots, cell)
                                                : field_frame_patterns(snapshots);
  std::string csv = "cycle [1],phase [1],time [sqrt(sigma/g)]";
  for (const char* field : {"mass", "height"})
    csv += fmt::format(",{0}_k [1/sigma],{0}_wavelength [sigma],{0}_a2 [1],{0}_a4 [1],{0}_a6 [1],{0}_symmetry,"
                       "{0}_order_parameter [{1}],{0}_correlation_previous_cycle [1],"
                       "{0}_half_wavelength_correlation [1]", field,
                       field == std::string("mass") ? "1/sigma^2" : "sigma");
  csv += "\n";
  struct PerPhase {
    std::vector<analysis::PatternMeasure> mass, height;
    std::vector<Correlations> mass_correlation, height_correlation;
  };
  std::vector<std::pair<double, PerPhase>> per_phase;
  for (std::size_t f = 0; f < frames.size(); ++f) {
    const auto& fr = frames[f];
    const auto before = previous_cycle(frames, f);
    const Correlations mass_c = correlations(before, frames, &FramePatterns::mass, f);
    const Correlations height_c = correlations(before, frames, &FramePatterns::height, f);
    csv += fmt::format("{},{},{},{},{}\n", fr.cycle, fr.phase, fr.time, measure_columns(fr.mass_measure, mass_c),
                       measure_columns(fr.height_measure, height_c));
    auto at = std::find_if(per_phase.begin(), per_phase.end(),
                           [&](const auto& entry) { return same_phase(entry.first, fr.phase); });
    if (at == per_phase.end()) at = per_phase.insert(per_phase.end(), {fr.phase, PerPhase{}});
    PerPhase& p = at->second;
    p.mass.push_back(fr.mass_measure), p.height.push_back(fr.height_measure);
    if (before) p.mass_correlation.push_back(mass_c), p.height_correlation.push_back(height_c);
  }
  std::sort(per_phase.begin(), per_phase.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  std::string summary;
  for (const auto& [phase, p] : per_phase)
    summary += summary_line(phase, "column mass", "1/sigma^2", p.mass, p.mass_correlation) +
               summary_line(phase, "centre-of-mass height", "sigma", p.height, p.height_correlation);
  return {std::move(csv), std::move(summary)};
}

}  // namespace shaker
