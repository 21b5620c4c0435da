#pragma once
// Helpers shared by the unit tests: a private temporary directory per test (so `ctest -j` is
// safe) and relative comparison with the measured error in the failure message.
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "common/errors.hpp"
#include "support/convergence.hpp"
#include "support/test_directory.hpp"

namespace shaker::testing {

/// A fresh directory named after the running test and the process; removed when the test
/// passes, kept when it fails (support/test_directory.hpp).
class TemporaryDirectory {
 public:
  TemporaryDirectory() : path_(test_directory()) {}
  TemporaryDirectory(const TemporaryDirectory&) = delete;
  TemporaryDirectory& operator=(const TemporaryDirectory&) = delete;
  const std::filesystem::path& path() const { return path_; }
  std::filesystem::path operator/(const std::string& name) const { return path_ / name; }

 private:
  std::filesystem::path path_;
};

using shaker::convergence::relative_error;

/// Runs f, expects InputError, and checks that the message contains every fragment; with
/// `seconds` > 0, also that the refusal took less than that.
inline void expect_input_error(const std::function<void()>& f, const std::vector<std::string>& fragments,
                               double seconds = 0.0) {
  const auto start = std::chrono::steady_clock::now();
  try {
    f();
    ADD_FAILURE() << "no InputError; expected a message with '" << fragments.front() << "'";
  } catch (const InputError& error) {
    const std::string message = error.what();
    for (const auto& fragment : fragments)
      EXPECT_NE(message.find(fragment), std::string::npos)
          << "message '" << message.substr(0, 400) << "' does not contain '" << fragment << "'";
  } catch (const std::exception& error) {
    ADD_FAILURE() << "threw something other than InputError: " << error.what();
  }
  if (seconds > 0.0) {
    EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), seconds);
  }
}

}  // namespace shaker::testing
