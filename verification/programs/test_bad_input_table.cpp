// The README's contract for bad input and failures, as data: every row of bad_input_cases.toml
// runs `shaker` in its own temporary directory (named after the case and the process id,
// removed when the case passes) and checks the exit code, a fragment of the message, the files
// that must not exist, must exist and must be left unchanged; no NAME.partial-PID file may be
// left in the directory. The columns are described at the top of the data file.
// SHAKER_PROGRAM is $<TARGET_FILE:shaker>, BAD_INPUT_CASES the data file, passed in by CMake.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/mount.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <thread>
#include <toml.hpp>
#include <vector>

#include "common/hdf5_file.hpp"

namespace {

namespace fs = std::filesystem;

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

/// "${repeat:N:TEXT}" stands for TEXT written N times (deeply nested input on one line).
std::string expand(std::string text) {
  for (std::size_t at; (at = text.find("${repeat:")) != std::string::npos;) {
    const std::size_t colon = text.find(':', at + 9), close = text.find('}', colon);
    const auto count = std::stoul(text.substr(at + 9, colon - at - 9));
    std::string repeated;
    for (std::size_t k = 0; k < count; ++k) repeated += text.substr(colon + 1, close - colon - 1);
    text.replace(at, close + 1 - at, repeated);
  }
  return text;
}

struct Case {
  std::string name;
  toml::value row;
};

const toml::value& table() {
  static const toml::value data = toml::parse(BAD_INPUT_CASES);
  return data;
}

std::vector<Case> load_cases() {
  std::vector<Case> cases;
  for (const auto& row : toml::find<toml::array>(table(), "cases"))
    cases.push_back({toml::find<std::string>(row, "name"), row});
  return cases;
}

// ---- fixtures: a small MD and continuum run with their checkpoints, made once ------------

struct Outcome {
  int exit_code = -1;  // 128 + signal if killed by one
  std::string output;  // stdout and stderr together
};

/// How a case runs shaker beyond its arguments.
struct Launch {
  int signal = 0;       ///< sent after `delay` seconds if > 0
  double delay = 0.0;
  std::string stdout_file;  ///< stdout goes there (opened for writing, not created) if not empty
  std::vector<std::string> prefix;  ///< a program that runs shaker (unshare ...), if not empty
};

/// A case still running after this long hangs: it is killed and fails with exit code -2.
constexpr double hang_seconds = 120.0;

/// Runs shaker ARGS in `dir` as `launch` says.
Outcome run_shaker(const fs::path& dir, const std::vector<std::string>& args, const Launch& launch = {}) {
  const fs::path log = dir / ".shaker-output";
  const pid_t pid = ::fork();
  if (pid == 0) {
    if (::chdir(dir.c_str()) != 0) ::_exit(99);
    const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int out = launch.stdout_file.empty() ? fd : ::open(launch.stdout_file.c_str(), O_WRONLY);
    ::dup2(out, 1);
    ::dup2(fd, 2);
    std::vector<std::string> words = launch.prefix;
    words.push_back(SHAKER_PROGRAM);
    words.insert(words.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (auto& w : words) argv.push_back(w.data());
    argv.push_back(nullptr);
    ::execvp(argv.front(), argv.data());
    ::_exit(98);
  }
  const auto start = std::chrono::steady_clock::now();
  const auto seconds = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  bool signalled = launch.signal == 0, hung = false;
  int status = 0;
  while (::waitpid(pid, &status, WNOHANG) == 0) {
    if (!signalled && seconds() >= launch.delay) {
      ::kill(pid, launch.signal);
      signalled = true;
    }
    if (seconds() > hang_seconds) {
      ::kill(pid, SIGKILL);
      ::waitpid(pid, &status, 0);
      hung = true;
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  Outcome r;
  r.output = read_text(log);
  fs::remove(log);
  r.exit_code = hung ? -2 : WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  if (hung) r.output += "\n[killed: still running after the test's limit]";
  return r;
}

/// Whether this process may make a private mount namespace (`unshare -rm`).
bool private_mounts_available() {
  static const bool available = std::system("unshare -rm true >/dev/null 2>&1") == 0;
  return available;
}

/// The type a special file of `kind` has outside the case's mount namespace.
fs::file_type special_file_type(const std::string& kind) {
  if (kind == "fifo") return fs::file_type::fifo;
  if (kind == "socket") return fs::file_type::socket;
  if (kind == "directory") return fs::file_type::directory;
  return fs::file_type::regular;  // the file a device was mounted on
}

/// Makes the special files of a case's `special` table: fifo, socket, directory; or
/// "device:/dev/X" (an empty file here, on which that device is bind-mounted in the case's own
/// mount namespace: the real device node is never an output).
void make_special_files(const fs::path& dir, const toml::value& row, Launch& launch) {
  for (const auto& [name, kind_value] : toml::find<toml::table>(row, "special")) {
    const fs::path path = dir / name;
    const std::string kind = kind_value.as_string().str;
    if (kind == "fifo") {
      ASSERT_EQ(::mkfifo(path.c_str(), 0644), 0) << path;
    } else if (kind == "directory") {
      fs::create_directories(path);
    } else if (kind == "socket") {
      const int fd = ::socket(AF_UNIX, SOCK_STREAM, 0);
      sockaddr_un address{};
      address.sun_family = AF_UNIX;
      ASSERT_LT(path.native().size(), sizeof(address.sun_path)) << path;
      std::strcpy(address.sun_path, path.c_str());
      ASSERT_EQ(::bind(fd, reinterpret_cast<sockaddr*>(&address), sizeof(address)), 0) << path;
      ::close(fd);
    } else if (kind.starts_with("device:")) {
      std::ofstream(path).put('\0');
      launch.prefix = {"unshare", "-rm", "sh", "-c", "mount --bind \"$1\" \"$2\" && shift 2 && exec \"$@\"",
                       "sh", kind.substr(7), path.string()};
    } else {
      FAIL() << "unknown special file kind " << kind;
    }
  }
}

class Fixtures : public ::testing::Environment {
 public:
  static fs::path directory() {
    return fs::temp_directory_path() / ("shaker-bad-input-fixtures-" + std::to_string(::getpid()));
  }
  void SetUp() override {
    const fs::path dir = directory();
    fs::remove_all(dir);
    fs::create_directories(dir);
    std::ofstream(dir / "case.toml") << toml::find<std::string>(table(), "case_toml");
    // One MD run gives a run file and an MD checkpoint; one continuum run its checkpoint.
    const Outcome md = run_shaker(dir, {"md", "case.toml", "--set", "run.output=run.h5", "--set",
                                        "run.checkpoint=md.ckpt.h5"});
    const Outcome continuum =
        run_shaker(dir, {"continuum", "case.toml", "--set", "run.output=continuum.h5", "--set",
                         "run.checkpoint=continuum.ckpt.h5"});
    // One frame of particles (the last cycle's phase 0) for the runs that start from a file.
    const Outcome snapshot = run_shaker(dir, {"md", "case.toml", "--set", "run.output=snap.h5", "--set",
                                              "md.snapshot_phases=[0]", "--set", "md.snapshot_cycles=[-1]"});
    ASSERT_EQ(md.exit_code, 0) << md.output;
    ASSERT_EQ(continuum.exit_code, 0) << continuum.output;
    ASSERT_EQ(snapshot.exit_code, 0) << snapshot.output;
    fs::copy_file(dir / "run.h5", dir / "ref.h5");
    fs::remove(dir / "continuum.h5");
    fs::remove(dir / "snap.h5");
    fs::remove(dir / "snap.particles.xyz");
  }
  void TearDown() override { fs::remove_all(directory()); }
};

// ---- damage recipes --------------------------------------------------------------------------

/// Replaces dataset `name` by `data` of shape `dims`.
void replace_dataset(hid_t file, const std::string& name, const std::vector<double>& data,
                     std::vector<std::size_t> dims) {
  H5Ldelete(file, name.c_str(), H5P_DEFAULT);
  if (dims.size() == 2)
    shaker::h5::write(file, name, data, dims[0], dims[1]);
  else if (dims.size() > 2)
    shaker::h5::write(file, name, data, dims, "1");
  else
    shaker::h5::write(file, name, data);
}

/// One step of a `damage` list: {file, op, ...}.
///   attr:    name = attribute, one of double / integer / string = the new value (any type)
///   doubles / integers: name = dataset, values = [...] (1D; replaces the dataset)
///   element: name = dataset, index, value: one element changed, shape kept
///   fill:    name = dataset, value: every element changed
///   bins:    name = a dataset or a group (all its matrices), bins: [phases x bins] matrices
///            cut to their first `bins` columns
///   phases:  name = dataset, rows: a [phases x bins] matrix cut to its first rows
///   bytes:   a plain file of `bytes` zero bytes (to fill a small file system)
///   delete:  name = a dataset or group, removed
void apply_damage(const fs::path& dir, const toml::value& step) {
  const auto path = dir / toml::find<std::string>(step, "file");
  const auto op = toml::find<std::string>(step, "op");
  if (op == "bytes") {
    std::ofstream(path, std::ios::binary) << std::string(toml::find<std::size_t>(step, "bytes"), '\0');
    return;
  }
  const auto name = toml::find<std::string>(step, "name");
  const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
  ASSERT_GE(file, 0) << path;
  if (op == "delete") {
    EXPECT_GE(H5Ldelete(file, name.c_str(), H5P_DEFAULT), 0) << name;
  } else if (op == "attr") {
    H5Adelete(file, name.c_str());
    if (step.contains("double")) shaker::h5::write_attribute(file, name, toml::find<double>(step, "double"));
    if (step.contains("integer"))
      shaker::h5::write_attribute(file, name, toml::find<std::int64_t>(step, "integer"));
    if (step.contains("string"))
      shaker::h5::write_attribute(file, name, toml::find<std::string>(step, "string"));
  } else if (op == "doubles") {
    replace_dataset(file, name, toml::find<std::vector<double>>(step, "values"), {});
  } else if (op == "integers") {
    const auto values = toml::find<std::vector<std::int64_t>>(step, "values");
    H5Ldelete(file, name.c_str(), H5P_DEFAULT);
    shaker::h5::write(file, name, values);
  } else if (op == "element" || op == "fill") {
    auto data = shaker::h5::read_doubles(file, name);
    const auto dims = shaker::h5::shape(file, name);
    const double value = toml::find<double>(step, "value");
    if (op == "fill")
      for (double& x : data) x = value;
    else
      data.at(toml::find<std::size_t>(step, "index")) = value;
    replace_dataset(file, name, data, dims);
  } else if (op == "bins" || op == "phases") {
    // A group: every matrix in it; a dataset: that one.
    std::vector<std::string> names{name};
    const shaker::h5::Handle object(H5Oopen(file, name.c_str(), H5P_DEFAULT));
    if (H5Iget_type(object.id()) == H5I_GROUP) {
      const shaker::h5::Handle group = shaker::h5::open_group(file, name);
      names.clear();
      for (const auto& member : shaker::h5::members(group.id())) names.push_back(name + "/" + member);
    }
    for (const auto& full : names) {
      const auto dims = shaker::h5::shape(file, full);
      // cycle_samples/cycles counts cycles per [phase x sample], not bins: it keeps its shape.
      // "phases" also cuts the per-phase vectors of a group (profiles/phase, profiles/time).
      const bool matrix = dims.size() == 2, per_phase = dims.size() == 1 && names.size() > 1;
      if (!(matrix || (op == "phases" && per_phase)) || (op == "bins" && full.ends_with("/cycles")))
        continue;
      const auto data = shaker::h5::read_doubles(file, full);
      const std::size_t width = matrix ? dims[1] : 1;
      const std::size_t rows = op == "phases" ? toml::find<std::size_t>(step, "rows") : dims[0];
      const std::size_t cols = op == "bins" ? toml::find<std::size_t>(step, "bins") : width;
      std::vector<double> cut;
      for (std::size_t r = 0; r < rows; ++r)
        for (std::size_t c = 0; c < cols; ++c) cut.push_back(data[r * width + c]);
      replace_dataset(file, full, cut, matrix ? std::vector<std::size_t>{rows, cols}
                                              : std::vector<std::size_t>{rows});
    }
  } else {
    ADD_FAILURE() << "unknown damage op " << op;
  }
  H5Fclose(file);
}

// ---- the test --------------------------------------------------------------------------------

class BadInput : public ::testing::TestWithParam<Case> {};

std::vector<std::string> strings(const toml::value& row, const char* key) {
  return row.contains(key) ? toml::find<std::vector<std::string>>(row, key)
                           : std::vector<std::string>{};
}

TEST_P(BadInput, MeetsTheContract) {
  const Case& c = GetParam();
  const toml::value& row = c.row;
  const fs::path dir =
      fs::temp_directory_path() / ("shaker-bad-input-" + c.name + "-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  for (const auto& entry : fs::directory_iterator(Fixtures::directory()))
    fs::copy_file(entry.path(), dir / entry.path().filename());
  if (row.contains("files"))
    for (const auto& [name, text] : toml::find<toml::table>(row, "files"))
      std::ofstream(dir / name) << expand(text.as_string().str);
  // A small file system (tmpfs of `tmpfs` bytes) mounted at dir/small, if this process may.
  const bool small_fs = row.contains("tmpfs");
  if (small_fs) {
    fs::create_directories(dir / "small");
    const std::string size = "size=" + std::to_string(toml::find<std::size_t>(row, "tmpfs"));
    if (::mount("tmpfs", (dir / "small").c_str(), "tmpfs", 0, size.c_str()) != 0) {
      fs::remove_all(dir);
      GTEST_SKIP() << "cannot mount a tmpfs (needs root / CAP_SYS_ADMIN): the full-disk case "
                      "is not run here";
    }
  }
  if (row.contains("damage"))
    for (const auto& step : toml::find<toml::array>(row, "damage")) apply_damage(dir, step);
  std::map<std::string, std::string> before;
  for (const auto& name : strings(row, "unchanged")) before[name] = read_text(dir / name);

  std::vector<std::string> args;
  for (const auto& a : strings(row, "args")) args.push_back(expand(a));
  Launch launch;
  launch.signal = row.contains("signal") ? toml::find<int>(row, "signal") : 0;
  launch.delay = row.contains("signal_after") ? toml::find<double>(row, "signal_after") : 0.0;
  if (row.contains("stdout")) launch.stdout_file = toml::find<std::string>(row, "stdout");
  if (row.contains("special")) make_special_files(dir, row, launch);
  if (HasFatalFailure()) return;
  if (!launch.prefix.empty() && !private_mounts_available()) {
    fs::remove_all(dir);
    GTEST_SKIP() << "no private mount namespace (unshare -rm): the device case is not run here; "
                    "the FIFO and socket cases check the same refusal by file type";
  }
  const Outcome r = run_shaker(dir, args, launch);

  SCOPED_TRACE(c.name + " in " + dir.string());
  EXPECT_EQ(r.exit_code, toml::find<int>(row, "exit")) << r.output.substr(0, 4000);
  for (const auto& fragment : strings(row, "message"))
    EXPECT_NE(r.output.find(fragment), std::string::npos)
        << "the output does not contain '" << fragment << "':\n" << r.output.substr(0, 4000);
  for (const auto& fragment : strings(row, "not_message"))
    EXPECT_EQ(r.output.find(fragment), std::string::npos)
        << "the output contains '" << fragment << "':\n" << r.output.substr(0, 4000);
  for (const auto& name : strings(row, "absent"))
    EXPECT_FALSE(fs::exists(dir / expand(name))) << name << " was written";
  for (const auto& name : strings(row, "present"))
    EXPECT_TRUE(fs::exists(dir / expand(name))) << name << " was not written";
  for (const auto& [name, text] : before)
    EXPECT_TRUE(read_text(dir / name) == text) << name << " was changed";
  if (row.contains("special")) {
    for (const auto& [name, kind] : toml::find<toml::table>(row, "special")) {
      EXPECT_EQ(fs::status(dir / name).type(), special_file_type(kind.as_string().str))
          << name << " (" << kind.as_string().str << ") was replaced";
    }
  }
  for (const auto& sub : {dir, dir / "small"}) {
    if (!fs::is_directory(sub)) continue;
    for (const auto& entry : fs::directory_iterator(sub))
      EXPECT_EQ(entry.path().filename().string().find(".partial-"), std::string::npos)
          << "left behind: " << entry.path();
  }
  if (small_fs) ::umount((dir / "small").c_str());
  if (!HasFailure()) fs::remove_all(dir);
}

INSTANTIATE_TEST_SUITE_P(Table, BadInput, ::testing::ValuesIn(load_cases()),
                         [](const ::testing::TestParamInfo<Case>& row) { return row.param.name; });

const auto* const fixtures = ::testing::AddGlobalTestEnvironment(new Fixtures);

}  // namespace
