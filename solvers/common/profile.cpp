#include "common/profile.hpp"

#include <algorithm>
#include <stdexcept>

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

}  // namespace shaker
