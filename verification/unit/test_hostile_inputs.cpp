// Hostile inputs to the readers of configuration and run files: deep nesting after every kind
// of string, long dotted keys, invalid UTF-8, sample shapes that would allocate without end
// (the fuzz targets of verification/fuzz found them), each fed to the reader through the
// normal build. The contract: InputError naming what is wrong, quickly.
#include <gtest/gtest.h>

#include <hdf5.h>

#include <string>
#include <vector>

#include "common/config.hpp"
#include "common/errors.hpp"
#include "common/hdf5_file.hpp"
#include "common/run_file.hpp"
#include "sample_run.hpp"
#include "test_support.hpp"

namespace {

using shaker::InputError;
using shaker::config::Config;
using shaker::testing::expect_input_error;

/// The pieces one after the other (appended: GCC 12 warns wrongly on long chains of +).
template <class... Pieces> std::string joined(const Pieces&... pieces) {
  std::string out;
  (out.append(pieces), ...);
  return out;
}

std::string repeated(const std::string& piece, int times) {
  std::string out;
  for (int k = 0; k < times; ++k) out += piece;
  return out;
}

// A multi-line string holding a quote ("""a"b""") ended the nesting check's string one quote
// early, so the check took the rest of the document for a string and let a deep array through
// to toml11's recursive parser: a stack overflow (SIGSEGV).
TEST(HostileConfiguration, DeepArrayAfterMultiLineStringWithQuoteIsRefused) {
  const std::string document = joined("[case]\nname = \"\"\"a\"b\"\"\"\n[md]\ncrossing_heights = ",
                                      repeated("[", 20000), repeated("]", 20000), "\n");
  expect_input_error([&] { Config::from_toml(document, "case.toml"); }, {"case.toml", "nested 20000 deep"});
  const std::string literal = joined("[case]\nname = '''a'b'''\n[md]\ncrossing_heights = ",
                                     repeated("[", 20000), repeated("]", 20000), "\n");
  expect_input_error([&] { Config::from_toml(literal, "case.toml"); }, {"case.toml", "nested"});
}

// Multi-line strings that end in their own quotes ("""a"""" holds a"), and escapes, still
// leave the rest of the document counted.
TEST(HostileConfiguration, NestingIsCountedAfterEveryKindOfString) {
  for (const std::string& string : std::vector<std::string>{"\"\"\"a\"\"\"\"", "\"\"\"a\"\"\"\"\"", "\"a\\\"b\"", "'a\\'",
                                   "'''a''''", "\"\"", "''"}) {
    const std::string document = joined("x = ", string, "\ny = ", repeated("[", 40), repeated("]", 40), "\n");
    expect_input_error([&] { Config::from_toml(document, "case.toml"); }, {"nested 40 deep"});
  }
}

// A dotted key or table header of 50,000 parts did not finish in 60 s (toml11 is quadratic in
// the parts: 8,000 took 2.4 s and 120 MB); it is refused before parsing.
TEST(HostileConfiguration, DeeplyDottedKeyIsRefusedQuickly) {
  expect_input_error([&] { Config::from_toml(joined("a", repeated(".a", 50000), " = 1\n"), "case.toml"); },
                     {"case.toml", "dotted-key parts nested"}, 1.0);
  expect_input_error([&] { Config::from_toml(joined("[a", repeated(".a", 50000), "]\nx = 1\n"), "case.toml"); },
                     {"case.toml", "nested"}, 1.0);
  expect_input_error([&] { Config::from_toml(joined("\"a\"", repeated(".\"a\"", 50000), " = 1\n"), "case.toml"); },
                     {"case.toml", "nested"}, 1.0);
}

// The nesting count does not refuse ordinary documents: numbers with dots, dates, the schema's
// two-part keys, a list.
TEST(HostileConfiguration, OrdinaryDocumentsPassTheNestingCheck) {
  const Config c = Config::from_toml(
      "[md]\ncrossing_heights = [10.5, 20.25, 1e3]\n[material]\ne = 0.5 # a.b.c.d\n"
      "[case]\nname = \"a.b.c.d.e.f.g.h.i.j.k.l.m.n.o.p.q.r.s.t.u.v.w.x.y.z.a.b.c.d.e.f.g.h\"\n",
      "case.toml");
  EXPECT_EQ(c.real("material.e"), 0.5);
  EXPECT_EQ(c.real_list("md.crossing_heights").size(), 3u);
}

// fuzz_config found that toml11 (3.7) reads past the end of its buffer when it reports an
// invalid UTF-8 sequence inside a literal string (an ASan heap-buffer-overflow; in a Release
// build an out-of-bounds read). Text that is not UTF-8 is now refused before toml11 sees it.
// The input is the fuzzer's, minimised by hand; the debug-asan preset runs this test under ASan.
TEST(HostileConfiguration, InvalidUtf8IsRefusedBeforeParsing) {
  expect_input_error([] { Config::from_toml("'a\xe4" "b' = 1\n", "case.toml"); },
                     {"case.toml", "not valid UTF-8 at byte 2 (line 1, byte 0xe4)"});
  expect_input_error(
      [] { Config::from_toml("' Thenotmd.gas_volume_fractionl\xe4re the per'sase # T-/case.et = \"fulsllsl\"", "case.toml"); },
      {"case.toml", "not valid UTF-8 at byte 31"});
  expect_input_error([] { Config().set("case.name='a\xe4" "b'"); }, {"--set case.name", "not valid UTF-8"});
  for (const char* bad : {"\xc0\xaf", "\xed\xa0\x80", "\xf4\x90\x80\x80", "\xe2\x82", "\x80"})
    expect_input_error([&] { Config::from_toml(joined("[case]\nname = \"", bad, "\"\n"), "case.toml"); },
                       {"not valid UTF-8 at byte 15 (line 2"});
  // Valid UTF-8 of every length still reads.
  EXPECT_EQ(Config::from_toml("[case]\nname = \"a\xc3\xa4\xe2\x82\xac\xf0\x9f\x98\x80\"\n", "case.toml").text("case.name"),
            "a\xc3\xa4\xe2\x82\xac\xf0\x9f\x98\x80");
}

// A run file whose profiles have 30,000 bins and whose cycle_samples/cycles matrix claims
// 30,000 samples per phase (a few MB in all) made the reader allocate the per-sample sums,
// 3 x 30,000 x 30,000 bins (108 GB), before it checked the sums' shapes: std::bad_alloc, exit 1.
// The shapes are now checked first.
TEST(HostileRunFile, SampleShapesAreCheckedBeforeTheSumsAreAllocated) {
  const shaker::testing::TemporaryDirectory dir;
  const auto path = dir / "huge-samples.h5";
  shaker::write_run_file(path, shaker::testing::make_sample_record(false));
  {
    namespace h5 = shaker::h5;
    h5::Handle file(H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT));
    ASSERT_GE(file.id(), 0);
    const std::size_t phases = shaker::testing::sample_phases, bins = 30000;
    const std::vector<double> ones(phases * bins, 1.0);
    {
      h5::Handle profiles = h5::open_group(file.id(), "profiles");
      for (const char* field : {"z", "n", "nu", "uz", "T"}) {
        H5Ldelete(profiles.id(), field, H5P_DEFAULT);
        h5::write(profiles.id(), field, ones, phases, bins);
      }
      for (const char* optional : {"samples", "n_se", "uz_se", "T_se"})
        if (h5::exists(profiles.id(), optional)) H5Ldelete(profiles.id(), optional, H5P_DEFAULT);
    }
    h5::Handle samples = h5::create_group(file.id(), "cycle_samples");
    h5::write_attribute(samples.id(), "bin_volume", 1.0);
    h5::write(samples.id(), "cycles", ones, phases, bins);  // 30,000 samples of one cycle each
    for (const char* sum : {"count", "vx", "vy", "vz", "v2"})
      h5::write(samples.id(), sum, std::vector<double>{1.0}, 1, 1);
  }
  expect_input_error([&] { shaker::read_run_file(path); },
                     {"huge-samples.h5", "cycle_samples/count is not a [90000 x 30000] matrix"}, 10.0);
}

}  // namespace
