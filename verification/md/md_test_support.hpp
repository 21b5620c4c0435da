#pragma once
// Small helpers shared by the MD tests.
#include <gtest/gtest.h>
#include <unistd.h>  // getpid

#include <cmath>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "md/geometry.hpp"
#include "md/simulation.hpp"
#include "support/test_directory.hpp"

namespace shaker::md::testing {

using shaker::testing::test_directory;

inline Vec3 total_momentum(const Simulation& s) {
  std::vector<Vec3> r, v;
  s.positions_at(s.time(), r, v);
  Vec3 sum;
  for (const Vec3& x : v) sum += x;
  return sum;
}

/// Equal bit for bit: NaN (an undefined profile value) equals NaN, -0.0 differs from 0.0.
inline bool bitwise_equal(const std::vector<double>& a, const std::vector<double>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0;
}

}  // namespace shaker::md::testing
