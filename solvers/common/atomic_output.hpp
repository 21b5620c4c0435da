#pragma once
// Atomic output: a file is written under a temporary name in its directory and renamed into
// place on success; on failure (an exception, a signal) the temporary file is removed and
// nothing exists under the output's name.
#include <hdf5.h>

#include <cstddef>
#include <filesystem>
#include <functional>
#include <string>

namespace shaker {

/// A file written under a temporary name and renamed into place by commit(). If the object
/// is destroyed without commit() (an exception, a bad input), the temporary file is removed
/// and nothing exists under the final name.
class AtomicOutput {
 public:
  /// A symbolic link under `final_path` stays: the file it points to is replaced.
  explicit AtomicOutput(const std::filesystem::path& final_path);
  AtomicOutput(const AtomicOutput&) = delete;
  AtomicOutput& operator=(const AtomicOutput&) = delete;
  ~AtomicOutput();
  const std::filesystem::path& temporary_path() const { return temporary_; }
  void commit();

 private:
  std::filesystem::path final_, temporary_;
  bool committed_ = false;
  int cleanup_slot_ = -1;  ///< slot in the signal handler's registry
};

/// `path` with its extension replaced by `extension` (".previous.h5"), the stem shortened where
/// the name would be longer than its file system allows: the files derived from an output
/// whose own name is at that limit.
std::filesystem::path derived_name(std::filesystem::path path, const std::string& extension);

/// Writes an HDF5 file atomically: `fill` writes into the new file (given its id), which is
/// then flushed and closed; any failure (a full disk) throws std::runtime_error naming `path`
/// and leaves nothing under that name.
void write_hdf5_atomically(const std::filesystem::path& path, const std::function<void(hid_t)>& fill);

/// Writes a text file atomically.
void write_text_atomically(const std::filesystem::path& path, const std::string& text);

/// Where an output goes: the file a symbolic link points to (the link is kept), else the path.
std::filesystem::path output_target(const std::filesystem::path& path);

/// The longest file name in `directory` (NAME_MAX of its file system; 255 if unknown).
std::size_t longest_name(const std::filesystem::path& directory);

}  // namespace shaker
