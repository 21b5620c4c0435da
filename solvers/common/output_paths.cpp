#include "common/output_paths.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "common/atomic_output.hpp"
#include "common/errors.hpp"

namespace shaker {

namespace {
std::filesystem::path resolved(const std::filesystem::path& path) {
  std::error_code error;
  auto full = std::filesystem::weakly_canonical(std::filesystem::absolute(path), error);
  return error ? std::filesystem::absolute(path).lexically_normal() : full;
}
}  // namespace

std::string file_type_name(const std::filesystem::path& path) {
  namespace fs = std::filesystem;
  switch (fs::status(path).type()) {
    case fs::file_type::regular: return "a regular file";
    case fs::file_type::directory: return "a directory";
    case fs::file_type::character: return "a character device";
    case fs::file_type::block: return "a block device";
    case fs::file_type::fifo: return "a FIFO (named pipe)";
    case fs::file_type::socket: return "a socket";
    case fs::file_type::not_found: return "missing";
    default: return "not a regular file";
  }
}

void check_input_file(const NamedPath& input) {
  if (std::filesystem::exists(input.path) && !std::filesystem::is_regular_file(input.path))
    throw InputError(fmt::format("{} '{}' is {}; allowed: a regular file", input.what,
                                 input.path.string(), file_type_name(input.path)));
}

void check_output_paths(const std::vector<NamedPath>& outputs, const std::vector<NamedPath>& inputs) {
  namespace fs = std::filesystem;
  for (std::size_t k = 0; k < outputs.size(); ++k) {
    const auto& [what, path] = outputs[k];
    if (path.empty())
      throw InputError(fmt::format("{} is empty: it must name the output file", what));
    if (path.filename().string().size() > longest_name(path.parent_path()))
      throw InputError(fmt::format("{} = \"{}\": the file name has {} bytes; allowed: at most {} "
                                   "(the file system's longest name)", what, path.string(),
                                   path.filename().string().size(), longest_name(path.parent_path())));
    if (fs::is_directory(path))
      throw InputError(fmt::format("{} = \"{}\" is a directory: it must name a file", what, path.string()));
    // A new output is renamed over the old file: a device or a FIFO would be replaced.
    if (fs::exists(path) && !fs::is_regular_file(path))
      throw InputError(fmt::format("{} = \"{}\" is {}: an output replaces the file under its name, "
                                   "so it must name a regular file or a new one", what,
                                   path.string(), file_type_name(path)));
    const fs::path target = output_target(path);
    const fs::path directory = target.has_parent_path() ? target.parent_path() : fs::path(".");
    if (!fs::is_directory(directory))
      throw InputError(fmt::format("{} = \"{}\": the directory '{}' does not exist", what,
                                   path.string(), directory.string()));
    // Writable for this process (root included): create and remove a probe file.
    const fs::path probe = directory / fmt::format(".shaker-probe-{}", ::getpid());
    const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL, 0600);
    if (fd < 0)
      throw InputError(fmt::format("{} = \"{}\": the directory '{}' is not writable ({})", what,
                                   path.string(), directory.string(), std::strerror(errno)));
    ::close(fd);
    ::unlink(probe.c_str());
    const fs::path full = resolved(path);
    for (const auto& input : inputs)
      if (!input.path.empty() && resolved(input.path) == full)
        throw InputError(fmt::format("{} = \"{}\" is the {} '{}': an output must not overwrite "
                                     "an input", what, path.string(), input.what, input.path.string()));
    for (std::size_t m = 0; m < k; ++m)
      if (resolved(outputs[m].path) == full)
        throw InputError(fmt::format("{} = \"{}\" and {} = \"{}\" are the same file: each output "
                                     "needs its own name", outputs[m].what, outputs[m].path.string(),
                                     what, path.string()));
  }
}

}  // namespace shaker
