#include "common/hdf5_file.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <optional>
#include <stdexcept>

#include "common/errors.hpp"
#include "common/output_paths.hpp"

namespace shaker::h5 {
namespace {

// HDF5 prints its error stack to stderr by default; the project reports errors itself.
// Files are closed by their handles; HDF5's own atexit clean-up is turned off, because after
// a failed write (a full disk) it closes the failed file again and crashes (SIGSEGV in
// H5F__close_cb, HDF5 1.10) instead of letting the program exit with its message.
struct SilenceHdf5 {
  SilenceHdf5() {
    H5dont_atexit();
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  }
};
const SilenceHdf5 silence;

hid_t checked(hid_t id, const std::string& what) {
  if (id < 0) throw std::runtime_error("HDF5: " + what + " failed");
  return id;
}
void checked_status(herr_t status, const std::string& what) {
  if (status < 0) throw std::runtime_error("HDF5: " + what + " failed");
}

Handle string_type() {
  Handle type(H5Tcopy(H5T_C_S1));
  checked_status(H5Tset_size(type.id(), H5T_VARIABLE), "string type");
  checked_status(H5Tset_cset(type.id(), H5T_CSET_UTF8), "string type");
  return type;
}

/// The creation properties of a dataset of `dims` whose first dimension is unlimited: chunks
/// of one row (one frame of an H5MD element; a whole 1D dataset).
Handle extendable_layout(const std::vector<hsize_t>& dims) {
  Handle properties(checked(H5Pcreate(H5P_DATASET_CREATE), "dataset creation properties"));
  std::vector<hsize_t> chunk = dims;
  if (chunk.size() == 1) chunk[0] = std::max<hsize_t>(chunk[0], 1);
  else chunk[0] = 1;
  for (hsize_t& c : chunk) c = std::max<hsize_t>(c, 1);
  checked_status(H5Pset_chunk(properties.id(), static_cast<int>(chunk.size()), chunk.data()),
                 "chunked layout");
  return properties;
}

template <class T>
Handle write_array(hid_t parent, const std::string& name, const T* data,
                   const std::vector<hsize_t>& dims, hid_t memory_type, hid_t file_type,
                   bool extendable = false) {
  std::vector<hsize_t> limits = dims;
  if (extendable && !limits.empty()) limits[0] = H5S_UNLIMITED;
  Handle space(checked(H5Screate_simple(static_cast<int>(dims.size()), dims.data(), limits.data()),
                       "dataspace for " + name));
  const Handle layout = extendable ? extendable_layout(dims) : Handle();
  Handle set(checked(H5Dcreate2(parent, name.c_str(), file_type, space.id(), H5P_DEFAULT,
                                extendable ? layout.id() : H5P_DEFAULT, H5P_DEFAULT),
                     "create dataset " + name));
  checked_status(H5Dwrite(set.id(), memory_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data),
                 "write dataset " + name);
  return set;
}

template <class T>
void write_with_units(hid_t parent, const std::string& name, const std::vector<T>& data,
                      const std::vector<std::size_t>& dims, const std::string& units,
                      hid_t memory_type, hid_t file_type, bool extendable = false) {
  std::size_t count = 1;
  for (const std::size_t d : dims) count *= d;
  if (count != data.size())
    throw std::logic_error(fmt::format("dataset {}: {} values for a shape of {} values", name,
                                       data.size(), count));
  const Handle set = write_array(parent, name, data.data(), std::vector<hsize_t>(dims.begin(), dims.end()),
                                 memory_type, file_type, extendable);
  write_attribute(set.id(), "units", units);
}

template <class T> std::vector<T> read_array(hid_t parent, const std::string& name, hid_t type) {
  if (!exists(parent, name)) throw InputError(fmt::format("dataset '{}' is missing", name));
  Handle set(checked(H5Dopen2(parent, name.c_str(), H5P_DEFAULT), "open dataset " + name));
  Handle space(checked(H5Dget_space(set.id()), "dataspace of " + name));
  const hssize_t count = H5Sget_simple_extent_npoints(space.id());
  std::vector<T> data(static_cast<std::size_t>(count));
  if (count > 0)
    checked_status(H5Dread(set.id(), type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data.data()),
                   "read dataset " + name);
  return data;
}

Handle open_attribute(hid_t object, const std::string& name) {
  if (!has_attribute(object, name)) throw InputError(fmt::format("attribute '{}' is missing", name));
  return Handle(checked(H5Aopen(object, name.c_str(), H5P_DEFAULT), "open attribute " + name));
}

/// A scalar attribute, or (`count` given) a one-dimensional array attribute of `count` values.
template <class T>
void write_scalar_attribute(hid_t object, const std::string& name, const T* value, hid_t type,
                            std::optional<hsize_t> count = std::nullopt) {
  Handle space(checked(count ? H5Screate_simple(1, &*count, nullptr) : H5Screate(H5S_SCALAR),
                       "attribute dataspace"));
  if (has_attribute(object, name)) H5Adelete(object, name.c_str());
  Handle attribute(checked(
      H5Acreate2(object, name.c_str(), type, space.id(), H5P_DEFAULT, H5P_DEFAULT),
      "create attribute " + name));
  checked_status(H5Awrite(attribute.id(), type, value), "write attribute " + name);
}

}  // namespace

Handle::Handle(hid_t id) : id_(id) {}
Handle::Handle(Handle&& other) noexcept : id_(other.id_) { other.id_ = H5I_INVALID_HID; }
Handle& Handle::operator=(Handle&& other) noexcept {
  std::swap(id_, other.id_);
  return *this;
}
Handle::~Handle() {
  if (id_ < 0) return;
  switch (H5Iget_type(id_)) {
    case H5I_FILE: H5Fclose(id_); break;
    case H5I_GROUP: H5Gclose(id_); break;
    case H5I_DATASET: H5Dclose(id_); break;
    case H5I_DATASPACE: H5Sclose(id_); break;
    case H5I_DATATYPE: H5Tclose(id_); break;
    case H5I_ATTR: H5Aclose(id_); break;
    default: break;
  }
}

Handle create_file(const std::filesystem::path& path) {
  return Handle(checked(H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT),
                        "create file " + path.string()));
}

void close_file(Handle& file) {
  checked_status(H5Fflush(file.id(), H5F_SCOPE_GLOBAL), "flush file");
  checked_status(H5Fclose(file.release()), "close file");  // the handle no longer owns it
}

Handle open_file(const std::filesystem::path& path) {
  if (!std::filesystem::exists(path))
    throw InputError(fmt::format("file '{}' does not exist", path.string()));
  check_input_file({"file", path});
  if (H5Fis_hdf5(path.c_str()) <= 0)
    throw InputError(fmt::format("file '{}' is not an HDF5 file", path.string()));
  const hid_t id = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (id < 0) throw InputError(fmt::format("cannot open HDF5 file '{}'", path.string()));
  return Handle(id);
}

Handle create_group(hid_t parent, const std::string& name) {
  return Handle(checked(H5Gcreate2(parent, name.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
                        "create group " + name));
}

Handle open_group(hid_t parent, const std::string& name) {
  if (!exists(parent, name)) throw InputError(fmt::format("group '{}' is missing", name));
  return Handle(checked(H5Gopen2(parent, name.c_str(), H5P_DEFAULT), "open group " + name));
}

bool exists(hid_t parent, const std::string& name) {
  return H5Lexists(parent, name.c_str(), H5P_DEFAULT) > 0;
}

std::vector<std::string> members(hid_t group) {
  H5G_info_t info;
  checked_status(H5Gget_info(group, &info), "group info");
  std::vector<std::string> names;
  for (hsize_t i = 0; i < info.nlinks; ++i) {
    const ssize_t size = H5Lget_name_by_idx(group, ".", H5_INDEX_CRT_ORDER, H5_ITER_INC, i,
                                            nullptr, 0, H5P_DEFAULT);
    if (size < 0) {  // creation order not tracked: fall back to name order
      names.clear();
      for (hsize_t j = 0; j < info.nlinks; ++j) {
        const ssize_t n = H5Lget_name_by_idx(group, ".", H5_INDEX_NAME, H5_ITER_INC, j, nullptr,
                                             0, H5P_DEFAULT);
        std::string name(static_cast<std::size_t>(n), '\0');
        H5Lget_name_by_idx(group, ".", H5_INDEX_NAME, H5_ITER_INC, j, name.data(),
                           static_cast<std::size_t>(n) + 1, H5P_DEFAULT);
        names.push_back(name);
      }
      return names;
    }
    std::string name(static_cast<std::size_t>(size), '\0');
    H5Lget_name_by_idx(group, ".", H5_INDEX_CRT_ORDER, H5_ITER_INC, i, name.data(),
                       static_cast<std::size_t>(size) + 1, H5P_DEFAULT);
    names.push_back(name);
  }
  return names;
}

void write(hid_t parent, const std::string& name, const std::vector<double>& data) {
  write_array(parent, name, data.data(), {data.size()}, H5T_NATIVE_DOUBLE, H5T_IEEE_F64LE);
}
void write(hid_t parent, const std::string& name, const std::vector<std::int64_t>& data) {
  write_array(parent, name, data.data(), {data.size()}, H5T_NATIVE_INT64, H5T_STD_I64LE);
}
void write(hid_t parent, const std::string& name, const std::vector<double>& data,
           std::size_t rows, std::size_t cols) {
  if (rows * cols != data.size())
    throw std::logic_error(fmt::format("dataset {}: {} values for a {}x{} matrix", name,
                                       data.size(), rows, cols));
  write_array(parent, name, data.data(), {rows, cols}, H5T_NATIVE_DOUBLE, H5T_IEEE_F64LE);
}
void write(hid_t parent, const std::string& name, const std::vector<double>& data,
           const std::vector<std::size_t>& dims, const std::string& units) {
  write_with_units(parent, name, data, dims, units, H5T_NATIVE_DOUBLE, H5T_IEEE_F64LE);
}
void write(hid_t parent, const std::string& name, const std::vector<std::int64_t>& data,
           const std::vector<std::size_t>& dims, const std::string& units) {
  write_with_units(parent, name, data, dims, units, H5T_NATIVE_INT64, H5T_STD_I64LE);
}
void write_extendable(hid_t parent, const std::string& name, const std::vector<double>& data,
                      const std::vector<std::size_t>& dims, const std::string& units) {
  write_with_units(parent, name, data, dims, units, H5T_NATIVE_DOUBLE, H5T_IEEE_F64LE, true);
}
void write_extendable(hid_t parent, const std::string& name, const std::vector<std::int64_t>& data,
                      const std::vector<std::size_t>& dims, const std::string& units) {
  write_with_units(parent, name, data, dims, units, H5T_NATIVE_INT64, H5T_STD_I64LE, true);
}
std::vector<double> read_doubles(hid_t parent, const std::string& name) {
  return read_array<double>(parent, name, H5T_NATIVE_DOUBLE);
}
std::vector<std::int64_t> read_integers(hid_t parent, const std::string& name) {
  return read_array<std::int64_t>(parent, name, H5T_NATIVE_INT64);
}

std::vector<double> read_row(hid_t parent, const std::string& name, std::size_t row) {
  std::vector<std::size_t> dims = shape(parent, name);
  if (dims.empty() || row >= dims[0])
    throw InputError(fmt::format("dataset '{}' has no row {} (shape [{}])", name, row, fmt::join(dims, ", ")));
  Handle set(checked(H5Dopen2(parent, name.c_str(), H5P_DEFAULT), "open dataset " + name));
  Handle space(checked(H5Dget_space(set.id()), "dataspace of " + name));
  std::vector<hsize_t> start(dims.size(), 0), count(dims.begin(), dims.end());
  start[0] = row;
  count[0] = 1;
  checked_status(H5Sselect_hyperslab(space.id(), H5S_SELECT_SET, start.data(), nullptr, count.data(), nullptr),
                 "select row of " + name);
  std::size_t values = 1;
  for (std::size_t k = 1; k < dims.size(); ++k) values *= dims[k];
  std::vector<double> data(values);
  const hsize_t memory_size = values;
  Handle memory(checked(H5Screate_simple(1, &memory_size, nullptr), "memory dataspace"));
  if (values > 0)
    checked_status(H5Dread(set.id(), H5T_NATIVE_DOUBLE, memory.id(), space.id(), H5P_DEFAULT, data.data()),
                   "read row of " + name);
  return data;
}

std::vector<std::size_t> shape(hid_t parent, const std::string& name) {
  if (!exists(parent, name)) throw InputError(fmt::format("dataset '{}' is missing", name));
  Handle set(checked(H5Dopen2(parent, name.c_str(), H5P_DEFAULT), "open dataset " + name));
  Handle space(checked(H5Dget_space(set.id()), "dataspace of " + name));
  const int rank = H5Sget_simple_extent_ndims(space.id());
  std::vector<hsize_t> dims(static_cast<std::size_t>(std::max(rank, 0)));
  H5Sget_simple_extent_dims(space.id(), dims.data(), nullptr);
  return {dims.begin(), dims.end()};
}

void write_attribute(hid_t object, const std::string& name, const std::string& value) {
  const Handle type = string_type();
  const char* text = value.c_str();
  write_scalar_attribute(object, name, &text, type.id());
}
void write_attribute(hid_t object, const std::string& name, double value) {
  write_scalar_attribute(object, name, &value, H5T_NATIVE_DOUBLE);
}
void write_attribute(hid_t object, const std::string& name, std::int64_t value) {
  write_scalar_attribute(object, name, &value, H5T_NATIVE_INT64);
}

void write_attribute(hid_t object, const std::string& name, const std::vector<std::int64_t>& values) {
  write_scalar_attribute(object, name, values.data(), H5T_NATIVE_INT64, values.size());
}
void write_attribute(hid_t object, const std::string& name, const std::vector<std::string>& values) {
  const Handle type = string_type();
  std::vector<const char*> texts;
  for (const std::string& value : values) texts.push_back(value.c_str());
  write_scalar_attribute(object, name, texts.data(), type.id(), texts.size());
}

std::string read_string_attribute(hid_t object, const std::string& name) {
  Handle attribute = open_attribute(object, name);
  const Handle type = string_type();
  char* text = nullptr;
  checked_status(H5Aread(attribute.id(), type.id(), &text), "read attribute " + name);
  std::string value = text ? text : "";
  H5free_memory(text);
  return value;
}
namespace {
/// The attribute's value as a number, whether stored as an integer or a real; InputError for a
/// string or any other type, or for more than one value.
Handle open_number_attribute(hid_t object, const std::string& name, H5T_class_t& type_class) {
  Handle attribute = open_attribute(object, name);
  const Handle type(checked(H5Aget_type(attribute.id()), "type of attribute " + name));
  const Handle space(checked(H5Aget_space(attribute.id()), "dataspace of attribute " + name));
  type_class = H5Tget_class(type.id());
  if (type_class != H5T_INTEGER && type_class != H5T_FLOAT)
    throw InputError(fmt::format("attribute '{}' is not a number (it is stored as {})", name,
                                 type_class == H5T_STRING ? "a string" : "another type"));
  if (H5Sget_simple_extent_npoints(space.id()) != 1)
    throw InputError(fmt::format("attribute '{}' holds {} values, not one number", name,
                                 H5Sget_simple_extent_npoints(space.id())));
  return attribute;
}
}  // namespace

double read_double_attribute(hid_t object, const std::string& name) {
  H5T_class_t type_class;
  const Handle attribute = open_number_attribute(object, name, type_class);
  double value = 0.0;
  checked_status(H5Aread(attribute.id(), H5T_NATIVE_DOUBLE, &value), "read attribute " + name);
  return value;
}
std::int64_t read_integer_attribute(hid_t object, const std::string& name) {
  H5T_class_t type_class;
  const Handle attribute = open_number_attribute(object, name, type_class);
  if (type_class == H5T_FLOAT) {  // only an exact integer stored as a real is one
    double value = 0.0;
    checked_status(H5Aread(attribute.id(), H5T_NATIVE_DOUBLE, &value), "read attribute " + name);
    if (!(std::trunc(value) == value && std::fabs(value) < 9.0e18))
      throw InputError(fmt::format("attribute '{}' = {} is not an integer", name, value));
    return static_cast<std::int64_t>(value);
  }
  std::int64_t value = 0;
  checked_status(H5Aread(attribute.id(), H5T_NATIVE_INT64, &value), "read attribute " + name);
  return value;
}
bool has_attribute(hid_t object, const std::string& name) {
  return H5Aexists(object, name.c_str()) > 0;
}

}  // namespace shaker::h5
