#pragma once
// Structs sent between ranks as arrays of doubles. A struct names its fields once, as a tuple
// of references (std::tie), and both directions walk that one list, so that a field added to
// it travels both ways and the order can never differ. Counts travel exactly below 2^53.
#include <tuple>
#include <vector>

namespace shaker {

/// Appends every field of `fields` (a std::tie of numbers and bools) to `out`.
template <class... T> void pack_fields(std::vector<double>& out, const std::tuple<T&...>& fields) {
  std::apply([&](const auto&... field) { (out.push_back(static_cast<double>(field)), ...); }, fields);
}

/// Reads every field of `fields` from `at` onwards, in the order pack_fields wrote them, and
/// moves `at` past them.
template <class... T> void unpack_fields(const double*& at, const std::tuple<T&...>& fields) {
  std::apply([&](auto&... field) { ((field = static_cast<std::remove_reference_t<decltype(field)>>(*at++)), ...); },
             fields);
}

}  // namespace shaker
