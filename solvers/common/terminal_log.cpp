#include "common/terminal_log.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <stdexcept>

#include "common/atomic_output.hpp"
#include "common/output_paths.hpp"
#include "common/run_file.hpp"
#include "common/version.hpp"

namespace shaker::terminal_log {
namespace {

std::atomic<int> log_descriptor{-1};
static_assert(std::atomic<int>::is_always_lock_free);

/// Writes all of `text` to `fd`; false on failure.
bool write_all(int fd, std::string_view text) {
  while (!text.empty()) {
    const ssize_t written = ::write(fd, text.data(), text.size());
    if (written < 0 && errno == EINTR) continue;
    if (written <= 0) return false;
    text.remove_prefix(static_cast<std::size_t>(written));
  }
  return true;
}

}  // namespace

std::filesystem::path path_for(const std::filesystem::path& output) { return derived_name(output, ".log"); }

void add_output(std::vector<NamedPath>& outputs, const RunProtocol& run) {
  if (run.log && !run.output.empty()) outputs.push_back({"run.output's log (run.log)", path_for(run.output)});
}

void start(const RunProtocol& run, const std::string& configuration) {
  if (!run.log || run.output.empty()) return;
  const std::filesystem::path path = path_for(run.output);
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0)
    throw std::runtime_error(fmt::format("cannot create the log {} ({})", path.string(), std::strerror(errno)));
  const std::string header = fmt::format(
      "# shaker {} ({}), started {}\n# what the terminal showed follows the effective configuration\n"
      "# ---- configuration ----\n{}# ---- terminal ----\n",
      program_version(), git_commit(), utc_now(), configuration);
  if (!write_all(fd, header)) {
    ::close(fd);
    throw std::runtime_error(fmt::format("cannot write the log {} ({})", path.string(), std::strerror(errno)));
  }
  if (const int previous = log_descriptor.exchange(fd); previous >= 0) ::close(previous);
}

void to_log(std::string_view text) {
  const int fd = log_descriptor.load();
  // A log that cannot be written (a full disk) must not end the run it records: it stops, once,
  // with a word on the terminal.
  if (fd >= 0 && !write_all(fd, text)) {
    log_descriptor.store(-1);
    ::close(fd);
    fmt::print(stderr, "shaker: warning: the log could not be written ({}); it stops here\n", std::strerror(errno));
  }
}

void print(std::FILE* stream, std::string_view text) {
  std::fwrite(text.data(), 1, text.size(), stream);
  std::fflush(stream);
  to_log(text);
}

int descriptor() { return log_descriptor.load(); }

}  // namespace shaker::terminal_log
