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

inline Vec3 total_momentum(const Simulation& s) {
  std::vector<Vec3> r, v;
  s.positions_at(s.time(), r, v);
  Vec3 sum;
  for (const Vec3& x : v) sum += x;
  return sum;
}

}  // namespace shaker::md::testing
