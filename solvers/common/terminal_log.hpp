#pragma once
// What a run shows on the terminal, kept in a log file beside its output (run.log), so that a
// run's messages, progress, summary and warnings survive the terminal that showed them.
#include <fmt/format.h>

#include <cstdio>
#include <filesystem>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "common/case_parameters.hpp"
#include "common/output_paths.hpp"

namespace shaker::terminal_log {

/// OUTPUT.log, the log of the run whose output is `output`.
std::filesystem::path path_for(const std::filesystem::path& output);

/// The log among a run's outputs, if it keeps one (checked with the others before any work).
void add_output(std::vector<NamedPath>& outputs, const RunProtocol& run);

/// If the run keeps a log (run.log), from here on what the program prints through print() also
/// goes to its log, path_for(run.output), up
/// to the end of the process (the message of a stop or failure included), or the next start().
/// Unlike the other outputs, the log is written as the run goes, not under a temporary name: a
/// run that is killed or fails leaves its log, which then says how far it got. Creates (or
/// replaces) the log and writes its header: program, commit, start time and the effective
/// configuration. Throws std::runtime_error if the log cannot be created.
void start(const RunProtocol& run, const std::string& configuration);

/// Writes `text` to `stream` and, once a log is started, to the log.
void print(std::FILE* stream, std::string_view text);
/// fmt::print to `stream`, and to the log.
template <class... Args> void say(std::FILE* stream, fmt::format_string<Args...> format, Args&&... args) {
  print(stream, std::string_view(fmt::format(format, std::forward<Args>(args)...)));
}
/// Writes `text` to the log only: the plain form of what the terminal shows in place (a live
/// progress line).
void to_log(std::string_view text);
/// The log's file descriptor, -1 before start() (async-signal safe: the signal handler
/// writes its last message there too).
int descriptor();

}  // namespace shaker::terminal_log
