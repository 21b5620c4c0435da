// A run stopped by SIGTERM at any stored phase and continued from its checkpoint ends as the
// uninterrupted run does: the same final checkpoint, the same profiles and per-cycle sums in
// its run file, bit for bit, and the uninterrupted run's time-series rows after the restart
// point. The stops are deterministic: the run's progress lines (one per stored phase) go to a
// stream whose writer raises SIGTERM at a chosen line, inside that phase's observers and before
// the checkpoint observer looks for a stop, so the run stops at that very phase.
#include <hdf5.h>
#include <stdio.h>  // fopencookie

#include <csignal>
#include <cstring>
#include <set>
#include <string>
#include <vector>

#include "common/checkpoints.hpp"
#include "common/config.hpp"
#include "common/hdf5_file.hpp"
#include "md/run_md.hpp"
#include "md_test_support.hpp"

namespace shaker::md {
namespace {

constexpr int phases = 10, transient = 2, sampled = 3;

config::Config small_case(const std::filesystem::path& dir, const std::string& name) {
  config::Config c;
  for (const std::string& setting : std::vector<std::string>{
           "layer.particles=200", "md.box_width=6.0", "md.ceiling=60.0", "md.crossing_heights=[12.5]",
        "run.phases_per_cycle=" + std::to_string(phases), "run.transient_cycles=" + std::to_string(transient),
        "run.sampled_cycles=" + std::to_string(sampled)})
    c.set(setting);
  c.set("run.output=" + (dir / (name + ".h5")).string());
  c.set("run.checkpoint=" + (dir / (name + ".ckpt.h5")).string());
  return c;
}

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
void datasets(hid_t file, const std::string& group, std::vector<std::string>& out) {
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
std::set<std::string> differing(const std::filesystem::path& a, const std::filesystem::path& b,
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

double attribute(const std::filesystem::path& path, const char* name) {
  const h5::Handle f = h5::open_file(path);
  return h5::read_double_attribute(f.id(), name);
}

/// Time-series columns counted from the start of each run (README, "Continuing").
bool run_relative(const std::string& column) {
  for (const char* name : {"plate_work", "collisional_loss", "energy_closure", "collisions"})
    if (column == name) return true;
  return column.rfind("crossings_z", 0) == 0 || column.rfind("particles_z", 0) == 0;
}

/// The columns of `continued`'s series that differ from `straight`'s last rows, and the rows
/// compared.
std::set<std::string> differing_rows(const std::filesystem::path& straight, const std::filesystem::path& continued,
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

TEST(MdContinuation, StoppedAtAnyStoredPhaseEndsAsTheStraightRun) {
  install_signal_cleanup();
  const auto dir = testing::test_directory();
  const ProgressSettings every_phase{false, 0.0};
  ASSERT_EQ(run(small_case(dir, "straight"), {}, every_phase), 0);
  // The stored phase (cycle, phase) at which the signal comes: in the transient, at the first
  // sampled phase, mid-way through sampled cycles, and at the last two phases of the run.
  const std::vector<std::pair<int, int>> stops{{1, 4}, {2, 0}, {2, 7}, {3, 3}, {4, 8}, {4, 9}};
  for (const auto& [cycle, phase] : stops) {
    const std::string name = "stop" + std::to_string(cycle) + "_" + std::to_string(phase);
    SCOPED_TRACE(name);
    int exit_code = 0;
    {
      // A line at every stored phase but the run's first (nothing done yet to report).
      const SignalAtLine signal(cycle * phases + phase - 1);
      try {
        run(small_case(dir, name), {}, every_phase);
      } catch (const StopRequested& stop) {
        exit_code = stop.exit_code();
      }
    }
    ASSERT_EQ(exit_code, 128 + SIGTERM);
    ASSERT_FALSE(std::filesystem::exists(dir / (name + ".h5")));
    const auto checkpoint = dir / (name + ".ckpt.h5");
    const std::int64_t next = cycle * phases + phase + 1;
    {
      const h5::Handle f = h5::open_file(checkpoint);
      EXPECT_EQ(h5::read_integer_attribute(f.id(), "schedule_cycle"), next / phases);
      EXPECT_EQ(h5::read_integer_attribute(f.id(), "schedule_phase"), next % phases);
    }
    config::Config rest = small_case(dir, name + "_rest");
    rest.set("run.restart_from=" + checkpoint.string());
    ASSERT_EQ(run(rest, {}, {true}), 0);
    EXPECT_EQ(differing(dir / "straight.ckpt.h5", dir / (name + "_rest.ckpt.h5"), ""), std::set<std::string>{});
    for (const char* name_of : {"time", "schedule_cycle", "schedule_phase"})
      EXPECT_EQ(attribute(dir / "straight.ckpt.h5", name_of), attribute(dir / (name + "_rest.ckpt.h5"), name_of))
          << name_of;
    EXPECT_EQ(differing(dir / "straight.h5", dir / (name + "_rest.h5"), "timeseries"), std::set<std::string>{});
    std::size_t rows = 0;
    EXPECT_EQ(differing_rows(dir / "straight.h5", dir / (name + "_rest.h5"), rows), std::set<std::string>{});
    // One row per stored phase after the restart point, and the end of the run.
    EXPECT_EQ(rows, static_cast<std::size_t>((transient + sampled) * phases - next + 1));
    std::printf("measured: stopped at cycle %d phase %d; continued %zu rows, equal to the straight run\n", cycle,
                phase, rows);
  }
}

}  // namespace
}  // namespace shaker::md
