#include "common/series_recorder.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <stdexcept>

namespace shaker {

EnergyBalance balance(const EnergyTotals& from, const EnergyTotals& to) {
  EnergyBalance b;
  b.drive_work = to.drive_work - from.drive_work;
  b.collisional_loss = to.collisional_loss - from.collisional_loss;
  b.floor_energy = to.floor_energy.value_or(0.0) - from.floor_energy.value_or(0.0);
  b.energy_change = to.energy - from.energy;
  b.residual = b.energy_change - b.drive_work + b.collisional_loss - b.floor_energy;
  const double scale = std::max({std::fabs(b.drive_work), std::fabs(b.collisional_loss), std::fabs(to.energy), 1e-300});
  b.relative_residual = std::fabs(b.residual) / scale;
  return b;
}

void SeriesRecorder::set(const std::string& name, double value) {
  const auto it = std::find(series_.names.begin(), series_.names.end(), name);
  if (it == series_.names.end()) {
    if (rows_ > 0) throw std::logic_error("time series column '" + name + "' is not one of the first row's");
    series_.names.push_back(name);
    series_.columns.push_back({value});
    return;
  }
  std::vector<double>& column = series_.columns[static_cast<std::size_t>(std::distance(series_.names.begin(), it))];
  if (column.size() != rows_) throw std::logic_error("time series column '" + name + "' set twice in a row");
  column.push_back(value);
}

void SeriesRecorder::set_energy(const EnergyTotals& now) {
  if (!first_) first_ = now;
  const EnergyBalance since_first = balance(*first_, now);
  set("accumulated_drive_work", now.drive_work);
  set("accumulated_collisional_loss", now.collisional_loss);
  if (now.floor_energy) set("accumulated_floor_energy", *now.floor_energy);
  set("energy_budget_residual", since_first.residual);
  set("energy_budget_relative_residual", since_first.relative_residual);
}

void SeriesRecorder::end_row() {
  for (std::size_t k = 0; k < series_.names.size(); ++k)
    if (series_.columns[k].size() != rows_ + 1)
      throw std::logic_error("time series column '" + series_.names[k] + "' not set in row " + std::to_string(rows_));
  ++rows_;
}

}  // namespace shaker
