#include "common/signals.hpp"

#include <unistd.h>

#include <atomic>
#include <csignal>
#include <cstring>

#include "common/terminal_log.hpp"

namespace shaker {

namespace {

// Temporary files in the making, for the signal handler: fixed slots of fixed size, claimed
// with an atomic flag, so that the handler reads them without locks or allocation.
constexpr int cleanup_slots = 32;
constexpr std::size_t cleanup_path_size = 4096;
struct CleanupSlot {
  std::atomic<bool> used{false};
  std::atomic<bool> ready{false};
  char path[cleanup_path_size];
};
CleanupSlot cleanup_registry[cleanup_slots];

/// To the terminal and the run's log (async-signal safe).
void write_stderr(const char* text) {
  for (const int fd : {2, terminal_log::descriptor()})
    if (fd >= 0) {
      const ssize_t ignored = ::write(fd, text, std::strlen(text));
      (void)ignored;
    }
}

extern "C" void remove_partial_files_and_exit(int signal) {
  int removed = 0;
  for (auto& slot : cleanup_registry)
    if (slot.ready.load() && ::unlink(slot.path) == 0) ++removed;
  // Only async-signal-safe calls here: write(2), unlink(2), _exit(2).
  char number[4] = {static_cast<char>('0' + signal / 10 % 10), static_cast<char>('0' + signal % 10), 0, 0};
  write_stderr("shaker: stopped by signal ");
  write_stderr(signal >= 10 ? number : number + 1);
  write_stderr(signal == SIGTERM ? " (SIGTERM)" : signal == SIGINT ? " (SIGINT)" : " (SIGHUP)");
  write_stderr(removed ? "; partial output files removed" : "; no partial output file");
  write_stderr(", nothing written under the output names\n");
  ::_exit(128 + signal);
}

// Read and written by the handler: lock-free atomics, which are async-signal safe.
std::atomic<bool> stop_deferred{false};
std::atomic<int> stop_signal{0};
static_assert(std::atomic<bool>::is_always_lock_free && std::atomic<int>::is_always_lock_free);

extern "C" void on_signal(int signal) {
  if (signal != SIGHUP && stop_deferred.load()) {
    int none = 0;
    if (stop_signal.compare_exchange_strong(none, signal)) return;
  }
  remove_partial_files_and_exit(signal);
}

}  // namespace

int register_for_cleanup(const std::filesystem::path& path) {
  const std::string& text = path.native();
  if (text.size() >= cleanup_path_size) return -1;
  for (int k = 0; k < cleanup_slots; ++k) {
    bool expected = false;
    if (!cleanup_registry[k].used.compare_exchange_strong(expected, true)) continue;
    std::memcpy(cleanup_registry[k].path, text.c_str(), text.size() + 1);
    cleanup_registry[k].ready.store(true);
    return k;
  }
  return -1;  // more than 32 files at once: not removed on a signal, still on an exception
}

void unregister_for_cleanup(int slot) {
  if (slot < 0) return;
  cleanup_registry[slot].ready.store(false);
  cleanup_registry[slot].used.store(false);
}

DeferredStop::DeferredStop() {
  stop_signal.store(0);
  stop_deferred.store(true);
}
DeferredStop::~DeferredStop() { stop_deferred.store(false); }
int DeferredStop::requested() { return stop_signal.load(); }

void install_signal_cleanup() {
  struct sigaction action {};
  action.sa_handler = on_signal;
  sigemptyset(&action.sa_mask);
  for (int s : {SIGTERM, SIGINT, SIGHUP}) sigaddset(&action.sa_mask, s);
  for (int s : {SIGTERM, SIGINT, SIGHUP}) ::sigaction(s, &action, nullptr);
}

}  // namespace shaker
