#pragma once
// Small helpers shared by the MD tests.
#include <gtest/gtest.h>
#include <unistd.h>  // getpid

#include <cmath>
#include <filesystem>
#include <string>

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

}  // namespace shaker::md::testing
