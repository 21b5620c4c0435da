// The run's log (run.log, docs/output-schema.md): what `shaker md` showed on the terminal,
// line for line, after a header with the program and the effective configuration; a run
// stopped by a failure leaves its log with the message.
#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "common/version.hpp"
#include "md_test_support.hpp"

namespace shaker::md {
namespace {

std::string text_of(const std::filesystem::path& path) {
  std::stringstream text;
  text << std::ifstream(path).rdbuf();
  return text.str();
}

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

/// Runs `shaker md` on a small case in `dir` with `settings`; returns its exit code.
int run_small_case(const std::filesystem::path& dir, const std::string& settings) {
  std::ofstream(dir / "case.toml") << "[layer]\nparticles = 100\n[md]\nbox_width = 5.0\nceiling = 60.0\n"
                                      "[run]\ntransient_cycles = 1\nsampled_cycles = 1\nphases_per_cycle = 10\n";
  const std::string command = std::string(SHAKER_BINARY) + " md " + (dir / "case.toml").string() +
                              " --set run.output=" + (dir / "run.h5").string() + " " + settings +
                              " > " + (dir / "stdout.txt").string() + " 2> " + (dir / "stderr.txt").string();
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST(MdRunLog, HoldsTheConfigurationAndEveryLineTheTerminalShowed) {
  const auto dir = testing::test_directory();
  // Progress at every stored phase: stderr is a file here, so it gets plain lines.
  ASSERT_EQ(run_small_case(dir, "--progress-interval 0"), 0) << text_of(dir / "stderr.txt");
  const std::string log = text_of(dir / "run.log");
  EXPECT_EQ(log.rfind(std::string("# shaker ") + program_version() + " (" + git_commit() + ")", 0), 0u)
      << log.substr(0, 200);
  EXPECT_NE(log.find("particles = 100"), std::string::npos);  // the effective configuration
  const std::size_t terminal = log.find("# ---- terminal ----\n");
  ASSERT_NE(terminal, std::string::npos);
  std::size_t shown = 0;
  for (const char* stream : {"stdout.txt", "stderr.txt"})
    for (const std::string& line : lines_of(text_of(dir / stream))) {
      EXPECT_NE(log.find(line + "\n", terminal), std::string::npos) << "not in the log: " << line;
      ++shown;
    }
  std::printf("%zu lines shown on the terminal, all in the log of %zu lines\n", shown, lines_of(log).size());
  EXPECT_GE(shown, 20u + 6u);  // a progress line per stored phase of two cycles, the summary
}

TEST(MdRunLog, ARunStoppedByCollapseExitsWithItsCodeAndLeavesItsLogWithTheMessage) {
  const auto dir = testing::test_directory();
  // Perfectly inelastic grains collapse at once without the guard: exit 3, no run file.
  ASSERT_EQ(run_small_case(dir, "--quiet --set material.e=0.0"), 3) << text_of(dir / "stderr.txt");
  EXPECT_FALSE(std::filesystem::exists(dir / "run.h5"));
  const std::string message = text_of(dir / "stderr.txt");
  ASSERT_FALSE(message.empty());
  EXPECT_NE(message.find("inelastic collapse"), std::string::npos) << message;
  EXPECT_NE(text_of(dir / "run.log").find(message), std::string::npos) << message;
}

TEST(MdRunLog, BadInputWritesNoLog) {
  const auto dir = testing::test_directory();
  ASSERT_EQ(run_small_case(dir, "--set material.e=1.5"), 2);
  EXPECT_FALSE(std::filesystem::exists(dir / "run.log"));
}

}  // namespace
}  // namespace shaker::md
