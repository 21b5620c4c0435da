#pragma once
// The time series as both solvers record it: one row per sampling instant, every value set by
// its column's name, and the energy budget's columns computed in one place, so both solvers'
// files speak one vocabulary (docs/output-schema.md, "Time series").
#include <optional>
#include <string>
#include <vector>

#include "common/profile.hpp"

namespace shaker {

/// A solver's running energy totals at one instant: the energy of the grains, the work the
/// drive has done on them, the energy their collisions have dissipated and (continuum only)
/// the energy the temperature floor has added. The totals continue across checkpoints.
struct EnergyTotals {
  double energy = 0.0, drive_work = 0.0, collisional_loss = 0.0;
  std::optional<double> floor_energy;
};

/// The energy budget between two instants: energy change = work - loss + floor energy, up to
/// the residual.
struct EnergyBalance {
  double drive_work = 0.0, collisional_loss = 0.0, floor_energy = 0.0, energy_change = 0.0;
  double residual = 0.0;
  /// |residual| / max(|work|, |loss|, |energy now|): what the budget leaves unexplained, as a
  /// share of its largest term.
  double relative_residual = 0.0;
};
EnergyBalance balance(const EnergyTotals& from, const EnergyTotals& to);

class SeriesRecorder {
 public:
  /// Sets a column of the current row; the first row declares the columns and their order.
  void set(const std::string& name, double value);
  /// The budget's columns: accumulated_drive_work, accumulated_collisional_loss and (when the
  /// totals have it) accumulated_floor_energy, as the running totals; energy_budget_residual
  /// and energy_budget_relative_residual since the first row.
  void set_energy(const EnergyTotals& now);
  /// Closes the row; throws std::logic_error if it misses a column.
  void end_row();
  std::size_t rows() const { return rows_; }
  const TimeSeries& series() const { return series_; }
  TimeSeries finish() { return std::move(series_); }

 private:
  TimeSeries series_;
  std::size_t rows_ = 0;
  std::optional<EnergyTotals> first_;
};

}  // namespace shaker
