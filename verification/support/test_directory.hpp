#pragma once
// One temporary directory per test and process (ctest -j safe, also with two ctest runs at
// once), shared by every GoogleTest program under verification/ (shaker_gtest defines
// SHAKER_TEST_FOLDER, the folder, for each). A directory is removed when its
// test ends without a failure, so a green run leaves nothing in the system temporary folder, and
// is kept (its path printed) when the test fails, so the failure can be inspected.
#include <gtest/gtest.h>
#include <unistd.h>  // getpid

#include <filesystem>
#include <iostream>
#include <string>
#include <system_error>
#include <vector>

namespace shaker::testing {

namespace detail {

// Told of every directory made during a test; GoogleTest calls OnTestEnd once the test's
// verdict is known, which a destructor inside the test body cannot see for later assertions.
class DirectoryCleaner : public ::testing::EmptyTestEventListener {
 public:
  void add(const std::filesystem::path& dir) { directories_.push_back(dir); }
  void OnTestEnd(const ::testing::TestInfo& info) override {
    for (const auto& dir : directories_) {
      if (info.result()->Failed()) {
        std::cout << "[ kept     ] " << dir.string() << " (the test failed)\n";
      } else {
        std::error_code ignored;
        std::filesystem::remove_all(dir, ignored);
      }
    }
    directories_.clear();
  }

 private:
  std::vector<std::filesystem::path> directories_;
};

inline DirectoryCleaner& cleaner() {
  // GoogleTest owns and deletes the listener; registering on first use keeps every test program
  // on gtest_main.
  static DirectoryCleaner* const instance = [] {
    auto* listener = new DirectoryCleaner;
    ::testing::UnitTest::GetInstance()->listeners().Append(listener);
    return listener;
  }();
  return *instance;
}

}  // namespace detail

#ifndef SHAKER_TEST_FOLDER
#error "SHAKER_TEST_FOLDER: declare the test program with shaker_gtest (cmake/ShakerTests.cmake)"
#endif

/// A fresh, empty directory `shaker-<folder>-<name>-<pid>` in the system temporary folder,
/// <folder> the test's folder under verification/; `name` defaults to the running test's suite
/// and name. Call it inside a test.
inline std::filesystem::path test_directory(std::string name = "") {
  const std::string prefix = std::string("shaker-") + SHAKER_TEST_FOLDER + "-";
  if (name.empty()) {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    name = std::string(info->test_suite_name()) + "-" + info->name();
  }
  for (char& c : name)
    if (c == '/') c = '_';
  const auto dir = std::filesystem::temp_directory_path() /
                   (prefix + name + "-" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  detail::cleaner().add(dir);
  return dir;
}

}  // namespace shaker::testing
