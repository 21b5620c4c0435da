// Regression cases of the fuzz targets (verification/fuzz): each input that crashed, hung or
// escaped with something other than InputError, fed to the same reader through the normal
// build. The contract: InputError naming what is wrong, quickly.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "common/config.hpp"
#include "common/errors.hpp"
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
TEST(FuzzRegressionConfig, DeepArrayAfterMultiLineStringWithQuoteIsRefused) {
  const std::string document = joined("[case]\nname = \"\"\"a\"b\"\"\"\n[md]\ncrossing_heights = ",
                                      repeated("[", 20000), repeated("]", 20000), "\n");
  expect_input_error([&] { Config::from_toml(document, "case.toml"); }, {"case.toml", "nested 20000 deep"});
  const std::string literal = joined("[case]\nname = '''a'b'''\n[md]\ncrossing_heights = ",
                                     repeated("[", 20000), repeated("]", 20000), "\n");
  expect_input_error([&] { Config::from_toml(literal, "case.toml"); }, {"case.toml", "nested"});
}

// Multi-line strings that end in their own quotes ("""a"""" holds a"), and escapes, still
// leave the rest of the document counted.
TEST(FuzzRegressionConfig, NestingIsCountedAfterEveryKindOfString) {
  for (const std::string& string : std::vector<std::string>{"\"\"\"a\"\"\"\"", "\"\"\"a\"\"\"\"\"", "\"a\\\"b\"", "'a\\'",
                                   "'''a''''", "\"\"", "''"}) {
    const std::string document = joined("x = ", string, "\ny = ", repeated("[", 40), repeated("]", 40), "\n");
    expect_input_error([&] { Config::from_toml(document, "case.toml"); }, {"nested 40 deep"});
  }
}

// A dotted key or table header of 50,000 parts did not finish in 60 s (toml11 is quadratic in
// the parts: 8,000 took 2.4 s and 120 MB); it is refused before parsing.
TEST(FuzzRegressionConfig, DeeplyDottedKeyIsRefusedQuickly) {
  expect_input_error([&] { Config::from_toml(joined("a", repeated(".a", 50000), " = 1\n"), "case.toml"); },
                     {"case.toml", "dotted-key parts nested"}, 1.0);
  expect_input_error([&] { Config::from_toml(joined("[a", repeated(".a", 50000), "]\nx = 1\n"), "case.toml"); },
                     {"case.toml", "nested"}, 1.0);
  expect_input_error([&] { Config::from_toml(joined("\"a\"", repeated(".\"a\"", 50000), " = 1\n"), "case.toml"); },
                     {"case.toml", "nested"}, 1.0);
}

// The nesting count does not refuse ordinary documents: numbers with dots, dates, the schema's
// two-part keys, a list.
TEST(FuzzRegressionConfig, OrdinaryDocumentsPassTheNestingCheck) {
  const Config c = Config::from_toml(
      "[md]\ncrossing_heights = [10.5, 20.25, 1e3]\n[material]\ne = 0.5 # a.b.c.d\n"
      "[case]\nname = \"a.b.c.d.e.f.g.h.i.j.k.l.m.n.o.p.q.r.s.t.u.v.w.x.y.z.a.b.c.d.e.f.g.h\"\n",
      "case.toml");
  EXPECT_EQ(c.real("material.e"), 0.5);
  EXPECT_EQ(c.real_list("md.crossing_heights").size(), 3u);
}

}  // namespace
