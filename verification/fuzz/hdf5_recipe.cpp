#include "hdf5_recipe.hpp"

#include <hdf5.h>
#include <unistd.h>

#include <cstdlib>
#include <cstring>
#include <mutex>
#include <string>
#include <vector>

#include "common/hdf5_file.hpp"

namespace shaker::fuzz {
namespace {

/// Reads the recipe; past its end every byte reads as zero and `exhausted` is set.
class Reader {
 public:
  Reader(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}
  bool at_end() const { return at_ >= size_; }
  bool exhausted() const { return exhausted_; }
  std::uint8_t byte() {
    if (at_ < size_) return data_[at_++];
    exhausted_ = true;
    return 0;
  }
  std::uint16_t u16() { return static_cast<std::uint16_t>(byte() | (byte() << 8)); }
  std::uint64_t u64() {
    std::uint64_t x = 0;
    for (int k = 0; k < 8; ++k) x |= static_cast<std::uint64_t>(byte()) << (8 * k);
    return x;
  }
  std::string text(std::size_t length) {
    std::string s;
    for (std::size_t k = 0; k < length; ++k) s.push_back(static_cast<char>(byte()));
    return s;
  }

 private:
  const std::uint8_t* data_;
  std::size_t size_, at_ = 0;
  bool exhausted_ = false;
};

enum class Type { float64, int64, text };

struct Record {
  std::string object, attribute;  // attribute empty: a dataset named `object`
  Type type = Type::float64;
  std::vector<hsize_t> dims;
  std::vector<std::uint64_t> numbers;  // raw 8-byte values
  std::vector<std::string> texts;
};

hid_t file_type(Type t) { return t == Type::float64 ? H5T_IEEE_F64LE : H5T_STD_I64LE; }
hid_t memory_type(Type t) { return t == Type::float64 ? H5T_NATIVE_DOUBLE : H5T_NATIVE_INT64; }

h5::Handle string_type() {
  h5::Handle type(H5Tcopy(H5T_C_S1));
  H5Tset_size(type.id(), H5T_VARIABLE);
  H5Tset_cset(type.id(), H5T_CSET_UTF8);
  return type;
}

/// The object an attribute goes on: the root, an existing object, or a new group.
h5::Handle object_for_attribute(hid_t file, const std::string& name, hid_t link_properties) {
  if (name.empty()) return h5::Handle(H5Oopen(file, "/", H5P_DEFAULT));
  if (H5Lexists(file, name.c_str(), H5P_DEFAULT) > 0) return h5::Handle(H5Oopen(file, name.c_str(), H5P_DEFAULT));
  return h5::Handle(H5Gcreate2(file, name.c_str(), link_properties, H5P_DEFAULT, H5P_DEFAULT));
}

void write_record(hid_t file, const Record& r, hid_t link_properties) {
  h5::Handle space(r.dims.empty() ? H5Screate(H5S_SCALAR)
                                  : H5Screate_simple(static_cast<int>(r.dims.size()), r.dims.data(), nullptr));
  if (space.id() < 0) return;
  const h5::Handle text_type = string_type();
  const hid_t stored = r.type == Type::text ? text_type.id() : file_type(r.type);
  const hid_t in_memory = r.type == Type::text ? text_type.id() : memory_type(r.type);
  std::vector<const char*> pointers;
  for (const auto& s : r.texts) pointers.push_back(s.c_str());
  const void* values = r.type == Type::text ? static_cast<const void*>(pointers.data())
                                            : static_cast<const void*>(r.numbers.data());
  if (r.attribute.empty()) {
    if (H5Lexists(file, r.object.c_str(), H5P_DEFAULT) > 0) H5Ldelete(file, r.object.c_str(), H5P_DEFAULT);
    h5::Handle set(H5Dcreate2(file, r.object.c_str(), stored, space.id(), link_properties,
                              H5P_DEFAULT, H5P_DEFAULT));
    if (set.id() >= 0) H5Dwrite(set.id(), in_memory, H5S_ALL, H5S_ALL, H5P_DEFAULT, values);
    return;
  }
  h5::Handle object = object_for_attribute(file, r.object, link_properties);
  if (object.id() < 0) return;
  if (H5Aexists(object.id(), r.attribute.c_str()) > 0) H5Adelete(object.id(), r.attribute.c_str());
  h5::Handle attribute(H5Acreate2(object.id(), r.attribute.c_str(), stored, space.id(),
                                  H5P_DEFAULT, H5P_DEFAULT));
  if (attribute.id() >= 0) H5Awrite(attribute.id(), in_memory, values);
}

}  // namespace

void write_hdf5_recipe(const std::filesystem::path& path, const std::uint8_t* data, std::size_t size) {
  // Records HDF5 refuses are expected here (a fuzzed name): no error stack on stderr.
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  h5::Handle file(H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT));
  if (file.id() < 0) std::abort();  // the harness's own temporary file: not the input's fault
  h5::Handle link_properties(H5Pcreate(H5P_LINK_CREATE));
  H5Pset_create_intermediate_group(link_properties.id(), 1);
  Reader in(data, size);
  while (!in.at_end()) {
    Record r;
    const std::string name = in.text(in.byte());
    const auto at = name.find('@');
    r.object = name.substr(0, at);
    if (at != std::string::npos) r.attribute = name.substr(at + 1);
    r.type = static_cast<Type>(in.byte() % 3);
    const int rank = in.byte() % 4;
    std::size_t count = 1;
    for (int k = 0; k < rank; ++k) {
      r.dims.push_back(in.u16());
      count *= static_cast<std::size_t>(r.dims.back());
    }
    if (count > max_recipe_elements) break;
    for (std::size_t k = 0; k < count; ++k) {
      if (r.type == Type::text) r.texts.push_back(in.text(in.u16()));
      else r.numbers.push_back(in.u64());
    }
    if ((r.object.empty() && r.attribute.empty()) || (at != std::string::npos && r.attribute.empty())) {
      if (in.exhausted()) break;
      continue;
    }
    write_record(file.id(), r, link_properties.id());
    if (in.exhausted()) break;
  }
  h5::close_file(file);
}

namespace {
std::vector<std::filesystem::path> files_to_remove;
void remove_private_files() {
  for (const auto& path : files_to_remove) {
    std::error_code ignored;
    std::filesystem::remove(path, ignored);
  }
}
}  // namespace

std::filesystem::path private_input_file(const char* target) {
  auto path = std::filesystem::temp_directory_path() /
              (std::string("shaker-fuzz-") + target + "-" + std::to_string(::getpid()) + ".h5");
  static std::once_flag registered;
  std::call_once(registered, [] { std::atexit(remove_private_files); });
  files_to_remove.push_back(path);
  return path;
}

}  // namespace shaker::fuzz
