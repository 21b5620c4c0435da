#pragma once
// What the tests of continued runs share: a stop signal at a chosen stored phase, raised by the
// run itself (deterministic), and comparisons of HDF5 files dataset by dataset, bit for bit.
//
// SignalAtLine: the run's progress lines (--progress-interval 0: one per stored phase but the
// run's first) go to a stream whose writer raises SIGTERM at a chosen line, inside that phase's
// observers and before the checkpoint observer looks for a stop, so the run stops at that very
// phase. The program's signal handling (install_signal_cleanup) must be installed.
#include <hdf5.h>
#include <stdio.h>  // fopencookie

#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <functional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "common/checkpoints.hpp"
#include "common/config.hpp"
#include "common/hdf5_file.hpp"
#include "common/progress.hpp"
#include "common/signals.hpp"
#include "gtest/gtest.h"

namespace shaker::testing {

/// stderr while it lives: a stream that raises SIGTERM when its `line`-th line (from 0) is
/// written, and keeps the text.
class SignalAtLine {
 public:
  explicit SignalAtLine(int line) : line_(line) {
    cookie_io_functions_t io{};
    io.write = [](void* self, const char* data, std::size_t size) -> ssize_t {
      static_cast<SignalAtLine*>(self)->take(data, size);
      return static_cast<ssize_t>(size);
    };
    stream_ = fopencookie(this, "w", io);
    setvbuf(stream_, nullptr, _IONBF, 0);
    saved_ = stderr;
    stderr = stream_;
  }
  ~SignalAtLine() {
    stderr = saved_;
    std::fclose(stream_);
  }
  const std::string& text() const { return text_; }

 private:
  void take(const char* data, std::size_t size) {
    for (std::size_t i = 0; i < size; ++i)
      if (data[i] == '\n' && lines_++ == line_) std::raise(SIGTERM);
    text_.append(data, size);
  }
  int line_, lines_ = 0;
  std::string text_;
  std::FILE* stream_;
  std::FILE* saved_;
};

/// The paths of every dataset in `group` of `file`, recursively.
inline void datasets(hid_t file, const std::string& group, std::vector<std::string>& out) {
  const h5::Handle g = h5::open_group(file, group);
  for (const std::string& name : h5::members(g.id())) {
    const std::string path = group == "/" ? name : group + "/" + name;
    hid_t sub = H5I_INVALID_HID;
    H5E_BEGIN_TRY { sub = H5Gopen2(file, path.c_str(), H5P_DEFAULT); }
    H5E_END_TRY;
    if (sub >= 0) {
      H5Gclose(sub);
      datasets(file, path, out);
    } else {
      out.push_back(path);
    }
  }
}

/// The datasets of two files that differ in their bits (read as doubles), or that one lacks;
/// those under `skip` are left out.
inline std::set<std::string> differing(const std::filesystem::path& a, const std::filesystem::path& b,
                                const std::string& skip) {
  const h5::Handle x = h5::open_file(a), y = h5::open_file(b);
  std::vector<std::string> in_x, in_y;
  datasets(x.id(), "/", in_x);
  datasets(y.id(), "/", in_y);
  std::set<std::string> out(in_y.begin(), in_y.end());
  for (const std::string& name : in_x) {
    if (!skip.empty() && name.rfind(skip, 0) == 0) {
      out.erase(name);
      continue;
    }
    if (!out.count(name)) {
      out.insert(name + " (missing)");
      continue;
    }
    const std::vector<double> u = h5::read_doubles(x.id(), name), v = h5::read_doubles(y.id(), name);
    if (u.size() == v.size() && std::memcmp(u.data(), v.data(), u.size() * sizeof(double)) == 0) out.erase(name);
  }
  return out;
}

inline double attribute(const std::filesystem::path& path, const char* name) {
  const h5::Handle f = h5::open_file(path);
  return h5::read_double_attribute(f.id(), name);
}

/// The columns of `continued`'s series that differ from `straight`'s last rows, and the rows
/// compared; columns for which `run_relative` is true (counted from the start of each run,
/// README "Continuing") are left out.
inline std::set<std::string> differing_rows(const std::filesystem::path& straight,
                                            const std::filesystem::path& continued,
                                            const std::function<bool(const std::string&)>& run_relative,
                                            std::size_t& rows) {
  const h5::Handle x = h5::open_file(straight), y = h5::open_file(continued);
  const h5::Handle a = h5::open_group(x.id(), "timeseries"), b = h5::open_group(y.id(), "timeseries");
  rows = h5::read_doubles(b.id(), "t").size();
  std::set<std::string> out;
  for (const std::string& name : h5::members(b.id())) {
    if (run_relative(name)) continue;
    const std::vector<double> all = h5::read_doubles(a.id(), name), part = h5::read_doubles(b.id(), name);
    if (part.size() > all.size() ||
        std::memcmp(all.data() + (all.size() - part.size()), part.data(), part.size() * sizeof(double)) != 0)
      out.insert(name);
  }
  return out;
}


/// What a continuation test runs: the solver's run(), a case writing `name`.h5 and
/// `name`.ckpt.h5 in the test's directory, and what is compared.
struct Continuation {
  std::function<int(const config::Config&, const ProgressSettings&)> run;
  std::function<config::Config(const std::string& name)> make_case;
  std::int64_t phases = 0, cycles = 0;  ///< of the case's schedule
  std::function<bool(const std::string&)> run_relative;  ///< series columns not compared
  bool same_run_file = false;  ///< the run file's datasets outside /timeseries equal too
};

/// Continuation::make_case for a case of `settings` whose outputs go to `dir`.
inline std::function<config::Config(const std::string&)> case_in(const std::filesystem::path& dir,
                                                                  const std::vector<std::string>& settings) {
  return [=](const std::string& name) {
    config::Config config;
    for (const std::string& setting : settings) config.set(setting);
    config.set("run.output=" + (dir / (name + ".h5")).string());
    config.set("run.checkpoint=" + (dir / (name + ".ckpt.h5")).string());
    return config;
  };
}

/// How often a case stores phases, and for how long it runs before and while it samples.
struct Schedule {
  int phases_per_cycle, transient_cycles, sampled_cycles;
};

/// The Continuation of the case `solver_settings` + `schedule` + `settings` (outputs in
/// `dir`), running `cycles` cycles with `run`; series columns where run_relative holds are
/// not compared.
inline Continuation continuation_of(std::function<int(const config::Config&, const ProgressSettings&)> run,
                                    const std::filesystem::path& dir, const Schedule& schedule,
                                    std::vector<std::string> solver_settings,
                                    const std::vector<std::string>& settings, std::int64_t cycles,
                                    std::function<bool(const std::string&)> run_relative) {
  solver_settings.push_back("run.phases_per_cycle=" + std::to_string(schedule.phases_per_cycle));
  solver_settings.push_back("run.transient_cycles=" + std::to_string(schedule.transient_cycles));
  solver_settings.push_back("run.sampled_cycles=" + std::to_string(schedule.sampled_cycles));
  solver_settings.insert(solver_settings.end(), settings.begin(), settings.end());
  Continuation c;
  c.run = std::move(run);
  c.make_case = case_in(dir, solver_settings);
  c.phases = schedule.phases_per_cycle;
  c.cycles = cycles;
  c.run_relative = std::move(run_relative);
  return c;
}

/// Runs the case straight, then stopped by SIGTERM at each stored phase (cycle, phase) of
/// `stops` and continued from its checkpoint; each continuation must end in the straight run's
/// final checkpoint, bit for bit, with the straight run's rows after its restart point.
inline void expect_continuations_exact(const std::filesystem::path& dir, const Continuation& c,
                                       const std::vector<std::pair<int, int>>& stops) {
  install_signal_cleanup();
  const ProgressSettings every_phase{false, 0.0};
  ASSERT_EQ(c.run(c.make_case("straight"), every_phase), 0);
  for (const auto& [cycle, phase] : stops) {
    const std::string name = "stop" + std::to_string(cycle) + "_" + std::to_string(phase);
    SCOPED_TRACE(name);
    int exit_code = 0;
    {
      const SignalAtLine signal(static_cast<int>(cycle * c.phases + phase - 1));
      try {
        c.run(c.make_case(name), every_phase);
      } catch (const StopRequested& stop) {
        exit_code = stop.exit_code();
      }
    }
    ASSERT_EQ(exit_code, 128 + SIGTERM);
    ASSERT_FALSE(std::filesystem::exists(dir / (name + ".h5")));
    const auto checkpoint = dir / (name + ".ckpt.h5");
    const std::int64_t next = cycle * c.phases + phase + 1;
    EXPECT_EQ(attribute(checkpoint, "schedule_cycle"), static_cast<double>(next / c.phases));
    EXPECT_EQ(attribute(checkpoint, "schedule_phase"), static_cast<double>(next % c.phases));
    config::Config rest = c.make_case(name + "_rest");
    rest.set("run.restart_from=" + checkpoint.string());
    ASSERT_EQ(c.run(rest, {true}), 0);
    const auto straight = dir / "straight.ckpt.h5", continued = dir / (name + "_rest.ckpt.h5");
    EXPECT_EQ(differing(straight, continued, ""), std::set<std::string>{});
    for (const char* attribute_name : {"time", "schedule_cycle", "schedule_phase"})
      EXPECT_EQ(attribute(straight, attribute_name), attribute(continued, attribute_name)) << attribute_name;
    if (c.same_run_file) {
      EXPECT_EQ(differing(dir / "straight.h5", dir / (name + "_rest.h5"), "timeseries"), std::set<std::string>{});
    }
    std::size_t rows = 0;
    EXPECT_EQ(differing_rows(dir / "straight.h5", dir / (name + "_rest.h5"), c.run_relative, rows),
              std::set<std::string>{});
    // One row per stored phase after the restart point (and, for the MD, the end of the run).
    EXPECT_GE(rows, static_cast<std::size_t>(c.cycles * c.phases - next));
    std::printf("measured: stopped at cycle %d phase %d; continued %zu rows, equal to the straight run\n", cycle,
                phase, rows);
  }
}

}  // namespace shaker::testing
