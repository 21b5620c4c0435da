#include "common/atomic_output.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <stdexcept>

#include "common/hdf5_file.hpp"
#include "common/signals.hpp"

namespace shaker {

std::size_t longest_name(const std::filesystem::path& directory) {
  const long limit = ::pathconf(directory.empty() ? "." : directory.c_str(), _PC_NAME_MAX);
  return limit > 0 ? static_cast<std::size_t>(limit) : 255;
}

namespace {
/// NAME.partial-PID beside NAME; when that is longer than the file system allows, NAME is
/// shortened and a hash of it keeps temporary names of different outputs apart.
std::filesystem::path temporary_name(const std::filesystem::path& final_path) {
  const std::string suffix = fmt::format(".partial-{}", ::getpid());
  const std::string name = final_path.filename().string();
  const std::size_t limit = longest_name(final_path.parent_path());
  if (name.size() + suffix.size() <= limit) return final_path.string() + suffix;
  const std::string tag = fmt::format("~{:016x}", std::hash<std::string>{}(name));
  const std::string kept = name.substr(0, limit - std::min(limit, suffix.size() + tag.size()));
  return final_path.parent_path() / (kept + tag + suffix);
}
}  // namespace

std::filesystem::path derived_name(std::filesystem::path path, const std::string& extension) {
  const std::string stem = path.stem().string();
  const std::size_t limit = longest_name(path.parent_path());
  if (stem.size() + extension.size() <= limit) return path.replace_extension(extension);
  return path.parent_path() / (stem.substr(0, limit - std::min(limit, extension.size())) + extension);
}

std::filesystem::path output_target(const std::filesystem::path& path) {
  std::error_code error;
  if (!std::filesystem::is_symlink(path, error)) return path;
  const auto target = std::filesystem::weakly_canonical(path, error);
  return error ? path : target;
}

AtomicOutput::AtomicOutput(const std::filesystem::path& final_path)
    : final_(output_target(final_path)), temporary_(temporary_name(final_)) {
  cleanup_slot_ = register_for_cleanup(temporary_);
}

AtomicOutput::~AtomicOutput() {
  if (!committed_) {
    std::error_code ignored;
    std::filesystem::remove(temporary_, ignored);
  }
  unregister_for_cleanup(cleanup_slot_);
}

void AtomicOutput::commit() {
  std::filesystem::rename(temporary_, final_);  // atomic within one file system
  committed_ = true;
  unregister_for_cleanup(cleanup_slot_);
  cleanup_slot_ = -1;
}

void write_hdf5_atomically(const std::filesystem::path& path, const std::function<void(hid_t)>& fill) {
  AtomicOutput output(path);
  try {
    h5::Handle file = h5::create_file(output.temporary_path());
    fill(file.id());
    h5::close_file(file);
  } catch (const std::runtime_error& error) {
    throw std::runtime_error(fmt::format("cannot write '{}' (disk full or an I/O error?): {}; "
                                         "nothing was written under that name", path.string(),
                                         error.what()));
  }
  output.commit();
}

void write_text_atomically(const std::filesystem::path& path, const std::string& text) {
  AtomicOutput output(path);
  {
    std::FILE* file = std::fopen(output.temporary_path().c_str(), "wb");
    if (!file) throw std::runtime_error("cannot write " + output.temporary_path().string());
    const bool ok = std::fwrite(text.data(), 1, text.size(), file) == text.size();
    if (std::fclose(file) != 0 || !ok)
      throw std::runtime_error("cannot write " + output.temporary_path().string());
  }
  output.commit();
}

}  // namespace shaker
