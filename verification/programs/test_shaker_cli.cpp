// The `shaker` program's handling of its command line and of bad input: help exits 0, a
// missing argument or bad input exits 2 with a message naming the key, and nothing is written
// under the output name. SHAKER_PROGRAM is $<TARGET_FILE:shaker>, passed in by CMake.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "common/run_file.hpp"
#include "sample_run.hpp"
#include "test_support.hpp"

namespace {

struct Result {
  int exit_code = -1;
  std::string output;  // stdout and stderr together
};

/// Runs `shaker ARGS` through the shell (arguments are single-quoted).
Result run_shaker(const std::vector<std::string>& args) {
  std::string command = std::string("'") + SHAKER_PROGRAM + "'";
  for (const auto& a : args) command += " '" + a + "'";
  command += " 2>&1";
  Result r;
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) return r;
  char buffer[4096];
  for (std::size_t n; (n = std::fread(buffer, 1, sizeof buffer, pipe)) > 0;)
    r.output.append(buffer, n);
  const int status = pclose(pipe);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

void write_file(const std::filesystem::path& path, const std::string& text) {
  std::ofstream(path) << text;
}

TEST(ShakerProgram, HelpExitsZeroForTheProgramAndEverySubcommand) {
  const Result top = run_shaker({"--help"});
  EXPECT_EQ(top.exit_code, 0) << top.output;
  for (const char* sub : {"md", "continuum", "config", "analyze", "compare"})
    EXPECT_NE(top.output.find(sub), std::string::npos) << "--help does not list " << sub;
  for (const char* sub : {"md", "continuum", "config", "analyze", "compare"}) {
    const Result r = run_shaker({sub, "--help"});
    EXPECT_EQ(r.exit_code, 0) << sub << " --help: " << r.output;
    EXPECT_FALSE(r.output.empty()) << sub;
  }
  for (const char* sub : {"md", "continuum", "config"})
    EXPECT_NE(run_shaker({sub, "--help"}).output.find("--set"), std::string::npos) << sub;
  EXPECT_EQ(run_shaker({"--version"}).exit_code, 0);
}

TEST(ShakerProgram, MissingArgumentsExitTwo) {
  const std::vector<std::vector<std::string>> calls = {{},
                                                       {"md"},
                                                       {"continuum"},
                                                       {"analyze"},
                                                       {"compare"},
                                                       {"compare", "only-one.h5"},
                                                       {"no-such-subcommand"},
                                                       {"config", "--set"}};
  for (const auto& args : calls) {
    const Result r = run_shaker(args);
    std::string shown;
    for (const auto& a : args) shown += a + " ";
    EXPECT_EQ(r.exit_code, 2) << "shaker " << shown << "-> " << r.output;
  }
}

struct BadCase {
  const char* file_text;  // nullptr: the good file plus `override`
  const char* override;   // --set argument or nullptr
  const char* key;        // what the message must name
};

TEST(ShakerProgram, BadInputExitsTwoNamingTheKeyAndWritesNothing) {
  const shaker::testing::TemporaryDirectory dir;
  write_file(dir / "good.toml", "[shaker]\ngamma = 3.0\n");
  const BadCase cases[] = {
      {"[material]\nee = 0.8\n", nullptr, "material.ee"},           // unknown key
      {"[materials]\ne = 0.8\n", nullptr, "materials.e"},           // unknown section
      {"[shaker]\ngamma = \"3\"\n", nullptr, "shaker.gamma"},       // string for a number
      {"[layer]\nparticles = 10.5\n", nullptr, "layer.particles"},  // float for an integer
      {"[material]\ne = 1.5\n", nullptr, "material.e"},             // out of range
      {"[layer]\nparticles = -3\n", nullptr, "layer.particles"},    // negative N
      {"[shaker]\ngamma = -1.0\n", nullptr, "shaker.gamma"},        // Gamma < 0
      {"[md]\nbox_width = 0.5\n", nullptr, "md.box_width"},         // narrower than a particle
      {"[material]\nrestitution = \"elastic\"\n", nullptr, "material.restitution"},  // choice
      {"[shaker\ngamma = 3.0\n", nullptr, "bad.toml"},  // malformed TOML
      {nullptr, "shaker.gamma=abc", "shaker.gamma"},    // malformed --set value
      {nullptr, "shaker.gamma", "shaker.gamma"},        // --set without '='
      {nullptr, "material.e=2", "material.e"},          // --set out of range
      {nullptr, "nosuch.key=1", "nosuch.key"},          // --set unknown key
  };
  for (const char* sub : {"md", "continuum", "config"})
    for (const auto& c : cases) {
      const auto output = dir / "out.h5";
      std::vector<std::string> args = {sub};
      if (c.file_text) {
        write_file(dir / "bad.toml", c.file_text);
        args.push_back((dir / "bad.toml").string());
      } else {
        args.push_back((dir / "good.toml").string());
        args.insert(args.end(), {"--set", c.override});
      }
      args.insert(args.end(), {"--set", "run.output=" + output.string()});
      const Result r = run_shaker(args);
      SCOPED_TRACE(std::string(sub) + " with " + (c.file_text ? c.file_text : c.override));
      EXPECT_EQ(r.exit_code, 2) << r.output;
      EXPECT_NE(r.output.find(c.key), std::string::npos)
          << "the message does not name '" << c.key << "': " << r.output;
      EXPECT_FALSE(std::filesystem::exists(output))
          << "something was written under the output name";
    }
  // Every file in the directory is one the test wrote.
  for (const auto& entry : std::filesystem::directory_iterator(dir.path()))
    EXPECT_TRUE(entry.path().filename() == "good.toml" || entry.path().filename() == "bad.toml")
        << "unexpected file " << entry.path();
}

TEST(ShakerProgram, MissingOrForeignFilesExitTwo) {
  const shaker::testing::TemporaryDirectory dir;
  write_file(dir / "not-hdf5.h5", "this is text, not HDF5\n");
  const std::vector<std::vector<std::string>> calls = {
      {"config", (dir / "missing.toml").string()},
      {"md", (dir / "missing.toml").string()},
      {"analyze", (dir / "missing.h5").string()},
      {"analyze", (dir / "not-hdf5.h5").string()},
      {"compare", (dir / "not-hdf5.h5").string(), (dir / "missing.h5").string()}};
  for (const auto& args : calls) {
    const Result r = run_shaker(args);
    EXPECT_EQ(r.exit_code, 2) << args[0] << " " << args[1] << ": " << r.output;
    EXPECT_NE(r.output.find(std::filesystem::path(args[1]).filename().string()), std::string::npos)
        << "the message does not name the file: " << r.output;
  }
}

TEST(ShakerProgram, ConfigPrintsTheEffectiveConfiguration) {
  const shaker::testing::TemporaryDirectory dir;
  write_file(dir / "case.toml", "[material]\ne = 0.8\n");
  const Result r =
      run_shaker({"config", (dir / "case.toml").string(), "--set", "shaker.gamma=4.5"});
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("e = 0.8\n"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("gamma = 4.5\n"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("particles = 3937\n"), std::string::npos) << r.output;
  // Dimensional keys carry their units as a TOML comment (the text still loads as a case).
  EXPECT_NE(r.output.find("frequency = 0.095  # sqrt(g/sigma)\n"), std::string::npos) << r.output;
}

TEST(ShakerProgram, AnalyzeAndCompareAcceptAValidRunFile) {
  const shaker::testing::TemporaryDirectory dir;
  shaker::write_run_file(dir / "sample.h5", shaker::testing::make_sample_record(true));
  const Result analyze = run_shaker({"analyze", (dir / "sample.h5").string()});
  EXPECT_EQ(analyze.exit_code, 0) << analyze.output;
  EXPECT_NE(analyze.output.find("synthetic"), std::string::npos) << analyze.output;
  const Result compare =
      run_shaker({"compare", (dir / "sample.h5").string(), (dir / "sample.h5").string()});
  EXPECT_EQ(compare.exit_code, 0) << compare.output;
}

std::string first_line(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  return line;
}

// Every column of the CSV tables carries its units in its header, "name [units]", as the
// JSON carries them, and compare's CSV has a units column.
TEST(ShakerProgram, CsvHeadersCarryUnits) {
  const shaker::testing::TemporaryDirectory dir;
  shaker::write_run_file(dir / "sample.h5", shaker::testing::make_sample_record(true));
  const std::string run = (dir / "sample.h5").string();
  const Result analyze = run_shaker({"analyze", run, "--quiet", "--csv", (dir / "phases.csv").string(),
                                     "--profiles-csv", (dir / "profiles.csv").string()});
  ASSERT_EQ(analyze.exit_code, 0) << analyze.output;
  const std::regex with_units(R"([A-Za-z_0-9]+ \[[^\]]+\])");
  for (const char* table : {"phases.csv", "profiles.csv"}) {
    const std::string header = first_line(dir / table);
    std::stringstream cells(header);
    int columns = 0;
    for (std::string cell; std::getline(cells, cell, ','); ++columns)
      EXPECT_TRUE(std::regex_match(cell, with_units)) << table << ": '" << cell << "'";
    EXPECT_GE(columns, 9) << header;
  }
  EXPECT_EQ(first_line(dir / "profiles.csv").rfind("phase [1],z [sigma],n [1/sigma^3],", 0), 0u);
  const Result compare = run_shaker({"compare", run, run, "--csv", (dir / "compare.csv").string()});
  ASSERT_EQ(compare.exit_code, 0) << compare.output;
  EXPECT_EQ(first_line(dir / "compare.csv"), "metric,value,error,units,replicates");
}

/// The cycle counts k of the progress lines "LABEL: cycle k of n, ..." (n must be `cycles`).
std::vector<int> progress_cycles(const std::string& output, const std::string& label, int cycles) {
  std::vector<int> found;
  const std::regex progress(label + R"(: cycle (\d+) of (\d+), t = [^,]+, [^,]+/s, .+ left)");
  for (std::sregex_iterator it(output.begin(), output.end(), progress), end; it != end; ++it) {
    EXPECT_EQ(std::stoi((*it)[2]), cycles) << it->str();
    found.push_back(std::stoi((*it)[1]));
  }
  return found;
}

// Progress on stderr when it is not a terminal (here a pipe): with --progress-interval 0 a
// line at every stored phase, cycle counts rising to the total; --quiet prints none; the
// summary states the wall time.
TEST(ShakerProgram, ProgressLinesOnAPipeAndNoneWhenQuiet) {
  const shaker::testing::TemporaryDirectory dir;
  write_file(dir / "tiny.toml",
             "[run]\ntransient_cycles = 1\nsampled_cycles = 2\nphases_per_cycle = 4\n"
             "[layer]\nparticles = 40\n[md]\nbox_width = 4.0\n[continuum]\ncell_size = 0.5\n");
  for (const std::string solver : {"md", "continuum"}) {
    SCOPED_TRACE(solver);
    const std::string label = "shaker " + solver, output = (dir / (solver + ".h5")).string();
    const std::vector<std::string> run = {solver, (dir / "tiny.toml").string(), "--set", "run.output=" + output};
    std::vector<std::string> args = run;
    args.insert(args.end(), {"--progress-interval", "0"});
    const Result every_phase = run_shaker(args);
    ASSERT_EQ(every_phase.exit_code, 0) << every_phase.output;
    const std::vector<int> cycles = progress_cycles(every_phase.output, label, 3);
    // Every stored phase but the first (nothing done yet), and the end of the run.
    ASSERT_EQ(cycles.size(), 3u * 4u) << every_phase.output;
    EXPECT_EQ(cycles.front(), 1);
    EXPECT_EQ(cycles.back(), 3);
    for (std::size_t i = 1; i < cycles.size(); ++i) EXPECT_GE(cycles[i], cycles[i - 1]) << every_phase.output;
    EXPECT_NE(every_phase.output.find("wall time "), std::string::npos) << every_phase.output;

    args = run;
    args.insert(args.end(), {"--progress-interval", "0", "--quiet"});
    const Result quiet = run_shaker(args);
    ASSERT_EQ(quiet.exit_code, 0) << quiet.output;
    EXPECT_TRUE(progress_cycles(quiet.output, label, 3).empty()) << quiet.output;
    EXPECT_EQ(quiet.output.find(": cycle "), std::string::npos) << quiet.output;

    // An interval longer than the run: no line.
    args = run;
    args.insert(args.end(), {"--progress-interval", "3600"});
    const Result hourly = run_shaker(args);
    ASSERT_EQ(hourly.exit_code, 0) << hourly.output;
    EXPECT_EQ(hourly.output.find(": cycle "), std::string::npos) << hourly.output;

    std::filesystem::remove(output);
    args = run;
    args.insert(args.end(), {"--progress-interval", "-1"});
    const Result bad = run_shaker(args);
    EXPECT_EQ(bad.exit_code, 2) << bad.output;
    EXPECT_NE(bad.output.find("--progress-interval: value '-1'"), std::string::npos) << bad.output;
    EXPECT_NE(bad.output.find("0 <= value <= 86400"), std::string::npos) << bad.output;
    EXPECT_FALSE(std::filesystem::exists(output));
  }
}

}  // namespace
