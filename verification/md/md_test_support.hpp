#pragma once
// Small helpers shared by the MD tests.
#include <gtest/gtest.h>
#include <unistd.h>  // getpid

#include <cmath>
#include <filesystem>
#include <string>

#include "md/geometry.hpp"
#include "md/simulation.hpp"

namespace shaker::md::testing {

/// A fresh directory for one test and process (ctest -j safe, also with two ctest runs at once).
inline std::filesystem::path test_directory() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  const auto dir = std::filesystem::temp_directory_path() /
                   (std::string("shaker-md-") + info->test_suite_name() + "-" + info->name() + "-" +
                    std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

/// Periodic cube without gravity holding n particles at volume fraction nu.
inline Geometry periodic_box(std::size_t n, double nu) {
  Geometry g;
  g.periodic_z = true;
  g.gravity = 0.0;
  g.width = g.height = std::cbrt(static_cast<double>(n) * pi / (6.0 * nu));
  return g;
}

inline Vec3 total_momentum(const Simulation& s) {
  std::vector<Vec3> r, v;
  s.positions_at(s.time(), r, v);
  Vec3 sum;
  for (const Vec3& x : v) sum += x;
  return sum;
}

}  // namespace shaker::md::testing
