#pragma once
// A thin RAII layer over the HDF5 C API, and atomic output (write to a temporary file in the
// same directory, rename on success, remove on failure).
#include <hdf5.h>

#include <cstdint>
#include <filesystem>
#include <functional>
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

/// Removes the temporary files of every live AtomicOutput when SIGTERM, SIGINT or SIGHUP
/// arrives, says so on stderr and exits with 128 + signal. The registry is signal safe (fixed
/// slots, no allocation in the handler). Installed once by the program's main.
void install_signal_cleanup();

/// While an object of this class lives (a solver's run loop with its checkpoint observer),
/// SIGTERM and SIGINT only record that a stop was asked for: the run polls requested() at its
/// stored phases, writes a checkpoint there and exits. A second such signal, or SIGHUP, stops at
/// once as install_signal_cleanup says.
class DeferredStop {
 public:
  DeferredStop();
  DeferredStop(const DeferredStop&) = delete;
  DeferredStop& operator=(const DeferredStop&) = delete;
  ~DeferredStop();
  /// The signal that asked for the stop, or 0.
  static int requested();
};

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
