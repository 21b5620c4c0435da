#pragma once
// HDF5 files described as byte strings ("recipes"), for the fuzz targets of the HDF5 readers.
//
// The fuzzers mutate a recipe, not the HDF5 bytes: libhdf5 is not built with the fuzzer's
// coverage instrumentation, so mutated HDF5 bytes give the fuzzer no guidance, and libhdf5
// leaks memory on damaged files (a leak report and a growing RSS within a minute), which
// would fail every run on a library defect outside the readers. A recipe always turns into a
// well-formed HDF5 file whose content (names, types, shapes, values) is what the fuzzer
// controls: exactly the part the project's readers must validate.
//
// A recipe is a sequence of records, each one attribute or dataset (all integers little-endian):
//   u8 name length, name   "group/dataset" for a dataset (groups are created as needed),
//                          "object@attribute" for an attribute ("@attribute": the root group)
//   u8 type                (mod 3) 0: float64, 1: int64, 2: variable-length UTF-8 string
//   u8 rank                (mod 4) 0: scalar, else that many dimensions
//   rank x u16             the dimensions
//   values                 numbers: 8 bytes each; strings: u16 length, then the bytes
// A record whose values run past the end of the input is completed with zeros (and ends the
// recipe); one with more than max_recipe_elements values ends the recipe. verification/fuzz/
// h5_to_recipe.py writes the recipe of an existing file (the seeds are real files).
#include <cstddef>
#include <cstdint>
#include <filesystem>

namespace shaker::fuzz {

inline constexpr std::size_t max_recipe_elements = std::size_t{1} << 17;

/// Writes the file the recipe describes at `path` (replacing it). A record that HDF5 refuses
/// (an empty or clashing name) is left out: the file is the recipe's valid part.
void write_hdf5_recipe(const std::filesystem::path& path, const std::uint8_t* data, std::size_t size);

/// A file in the temporary directory private to this process (pid in its name), removed when
/// the process exits: fuzzers run as parallel jobs share /tmp.
std::filesystem::path private_input_file(const char* target);

}  // namespace shaker::fuzz
