#include "common/profile.hpp"

#include <algorithm>
#include <stdexcept>

#include <fmt/format.h>

#include "common/errors.hpp"

namespace shaker {

void TimeSeries::add(const std::string& name, std::vector<double> values) {
  if (!columns.empty() && values.size() != columns.front().size())
    throw std::logic_error("time series column '" + name + "' has a different length");
  if (has(name)) throw std::logic_error("time series column '" + name + "' added twice");
  names.push_back(name);
  columns.push_back(std::move(values));
}

const std::vector<double>& TimeSeries::column(const std::string& name) const {
  const auto it = std::find(names.begin(), names.end(), name);
  if (it == names.end()) throw std::out_of_range("no time series column '" + name + "'");
  return columns[static_cast<std::size_t>(it - names.begin())];
}

bool TimeSeries::has(const std::string& name) const {
  return std::find(names.begin(), names.end(), name) != names.end();
}

RunRecord pool_runs(const std::vector<RunRecord>& runs) {
  if (runs.empty()) throw InputError("no run to pool");
  RunRecord pooled = runs.front();
  if (runs.size() == 1) return pooled;
  for (std::size_t r = 1; r < runs.size(); ++r) {
    if (runs[r].samples.empty() || runs.front().samples.empty())
      throw InputError("only MD runs that keep their per-cycle sums can be pooled");
    if (runs[r].profiles.size() != pooled.profiles.size())
      throw InputError(fmt::format("the runs to pool store {} and {} phases",
                                   pooled.profiles.size(), runs[r].profiles.size()));
    try {
      pooled.samples.append(runs[r].samples);
    } catch (const std::invalid_argument& error) {
      throw InputError(error.what());
    }
  }
  for (std::size_t k = 0; k < pooled.profiles.size(); ++k) pooled.samples.pool(k, pooled.profiles[k]);
  pooled.model_variant += fmt::format(" (pooled over {} runs)", runs.size());
  return pooled;
}

}  // namespace shaker
