#pragma once
// Which paths the program may read and write, checked before any work.
#include <filesystem>
#include <string>
#include <vector>

namespace shaker {

/// A file the program reads or writes, named by the key or option that gave it.
struct NamedPath {
  std::string what;  ///< "run.output", "--csv", "configuration file", ...
  std::filesystem::path path;
};
/// Checked before any work (InputError naming the key and the path): every output is not empty,
/// a regular file if it exists (never a directory, device, FIFO or socket: it is replaced by a
/// rename), a name the file system allows, in an existing writable directory, and differs from
/// every input and from every other output (compared after resolving ".", ".." and symbolic
/// links).
void check_output_paths(const std::vector<NamedPath>& outputs, const std::vector<NamedPath>& inputs);
/// An input that exists must be a regular file (InputError naming it otherwise): opening a
/// FIFO would wait for a writer forever, a device would be read without end.
void check_input_file(const NamedPath& input);
/// "a regular file", "a FIFO (named pipe)", "a character device", ... (symbolic links followed).
std::string file_type_name(const std::filesystem::path& path);

}  // namespace shaker
