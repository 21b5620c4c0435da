#pragma once
// A thin RAII layer over the HDF5 C API.
#include <hdf5.h>

#include <cstdint>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace shaker::h5 {

/// Owns one HDF5 identifier and closes it with the right H5?close.
class Handle {
 public:
  Handle() = default;
  explicit Handle(hid_t id);
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  Handle(Handle&& other) noexcept;
  Handle& operator=(Handle&& other) noexcept;
  ~Handle();
  hid_t id() const { return id_; }
  /// Gives up ownership without closing.
  hid_t release() { return std::exchange(id_, H5I_INVALID_HID); }

 private:
  hid_t id_ = H5I_INVALID_HID;
};

Handle create_file(const std::filesystem::path& path);  ///< truncates
/// Flushes and closes a file being written, throwing if either fails (a full disk, an I/O
/// error): call it before AtomicOutput::commit, so that a failed write is never committed.
void close_file(Handle& file);
Handle open_file(const std::filesystem::path& path);    ///< read only; InputError if not HDF5
Handle create_group(hid_t parent, const std::string& name);
Handle open_group(hid_t parent, const std::string& name);
bool exists(hid_t parent, const std::string& name);
std::vector<std::string> members(hid_t group);

void write(hid_t parent, const std::string& name, const std::vector<double>& data);
void write(hid_t parent, const std::string& name, const std::vector<std::int64_t>& data);
/// Row-major matrix (rows x cols).
void write(hid_t parent, const std::string& name, const std::vector<double>& data,
           std::size_t rows, std::size_t cols);
/// An array of any shape (`dims` slowest first, the data in C order) with its units as the
/// string attribute `units` (docs/units.md notation; "1" for pure numbers).
void write(hid_t parent, const std::string& name, const std::vector<double>& data,
           const std::vector<std::size_t>& dims, const std::string& units);
void write(hid_t parent, const std::string& name, const std::vector<std::int64_t>& data,
           const std::vector<std::size_t>& dims, const std::string& units);
/// The same, chunked with an unlimited first dimension, as H5MD's time-dependent datasets are
/// (a reader may append rows).
void write_extendable(hid_t parent, const std::string& name, const std::vector<double>& data,
                      const std::vector<std::size_t>& dims, const std::string& units);
void write_extendable(hid_t parent, const std::string& name, const std::vector<std::int64_t>& data,
                      const std::vector<std::size_t>& dims, const std::string& units);
std::vector<double> read_doubles(hid_t parent, const std::string& name);
std::vector<std::int64_t> read_integers(hid_t parent, const std::string& name);
/// Row `row` of a dataset (the values at that index of its first dimension), as doubles.
std::vector<double> read_row(hid_t parent, const std::string& name, std::size_t row);
/// Dimensions of a dataset.
std::vector<std::size_t> shape(hid_t parent, const std::string& name);

void write_attribute(hid_t object, const std::string& name, const std::string& value);
void write_attribute(hid_t object, const std::string& name, double value);
void write_attribute(hid_t object, const std::string& name, std::int64_t value);
/// One-dimensional array attributes.
void write_attribute(hid_t object, const std::string& name, const std::vector<std::int64_t>& values);
void write_attribute(hid_t object, const std::string& name, const std::vector<std::string>& values);
std::string read_string_attribute(hid_t object, const std::string& name);
double read_double_attribute(hid_t object, const std::string& name);
std::int64_t read_integer_attribute(hid_t object, const std::string& name);
bool has_attribute(hid_t object, const std::string& name);

}  // namespace shaker::h5
