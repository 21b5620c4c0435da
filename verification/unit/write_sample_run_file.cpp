// Writes the sample run (sample_run.hpp) to the path given on the command line, for the
// h5py check (test_run_file_h5py.py). Exit code 0 on success.
#include <cstdio>
#include <exception>

#include "common/run_file.hpp"
#include "sample_run.hpp"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: write_sample_run_file OUTPUT.h5\n");
    return 2;
  }
  try {
    shaker::write_run_file(argv[1], shaker::testing::make_sample_record(true));
  } catch (const std::exception& error) {
    std::fprintf(stderr, "write_sample_run_file: %s\n", error.what());
    return 1;
  }
  return 0;
}
