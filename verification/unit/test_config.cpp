// Unit tests of the configuration (solvers/common/config.hpp) and of the typed view both
// solvers read (case_parameters.hpp): defaults, every kind of bad input, --set overrides, the
// TOML round trip of the effective configuration and its hash.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <functional>
#include <set>
#include <string>
#include <vector>

#include "common/case_parameters.hpp"
#include "common/config.hpp"
#include "common/errors.hpp"
#include "test_support.hpp"

namespace {

using shaker::InputError;
using shaker::config::Config;

using shaker::testing::expect_input_error;

void expect_bad_document(const std::string& toml, const std::vector<std::string>& fragments) {
  SCOPED_TRACE(toml);
  expect_input_error([&] { Config::from_toml(toml, "case.toml"); }, fragments);
}

void write_file(const std::filesystem::path& path, const std::string& text) {
  std::ofstream(path) << text;
}

// ---- defaults -------------------------------------------------------------------------------

TEST(Config, DefaultsReproduceThePaperBaseCase) {
  const Config c;
  EXPECT_EQ(c.real("shaker.gamma"), 3.0);
  EXPECT_EQ(c.real("shaker.frequency"), 0.095);
  EXPECT_EQ(c.text("material.restitution"), "constant");
  EXPECT_EQ(c.real("material.e"), 0.9);
  EXPECT_EQ(c.integer("layer.particles"), 3937);
  EXPECT_EQ(c.real("md.box_width"), 20.0);
  EXPECT_EQ(c.real("md.ceiling"), 200.0);
  EXPECT_EQ(c.real("md.bin_height"), 1.0);
  EXPECT_EQ(c.real("continuum.box_width"), 11.0);
  EXPECT_EQ(c.real("continuum.ceiling"), 80.0);
  EXPECT_EQ(c.text("continuum.transport"), "full");  // the validation cases' model
  EXPECT_EQ(c.integer("run.sampled_cycles"), 10);  // the paper averages over 10 cycles

  const auto p = shaker::CaseParameters::from(c);
  EXPECT_NEAR(p.shaker.amplitude(), 8.4200, 5e-5);  // docs/models.md: A = 8.42
  EXPECT_NEAR(p.shaker.period(), 10.526, 5e-4);
  EXPECT_EQ(p.restitution.kind, shaker::Restitution::Kind::constant);
  EXPECT_EQ(p.restitution(0.1), 0.9);
  EXPECT_EQ(p.particles, 3937);
  EXPECT_EQ(p.mass_per_area(), 3937.0 / 400.0);  // 10 per unit area for H = 9
  EXPECT_EQ(p.run.kind, shaker::RunProtocol::Kind::periodic);
  EXPECT_EQ(p.run.phases_per_cycle, 50);
}

TEST(Config, SchemaIsSelfConsistent) {
  std::set<std::string> keys;
  for (const auto& spec : shaker::config::schema()) {
    SCOPED_TRACE(spec.key);
    EXPECT_TRUE(keys.insert(spec.key).second) << "duplicate key";
    EXPECT_NE(spec.key.find('.'), std::string::npos) << "key without a section";
    EXPECT_FALSE(spec.meaning.empty());
    // Every default passes its own validation.
    EXPECT_NO_THROW(Config().set_value(spec.key, spec.default_value));
  }
  EXPECT_GE(keys.size(), 30u);
}

// ---- bad input, each kind -----------------------------------------------------------------

TEST(Config, RejectsUnknownKeyNamingItAndTheKnownKeys) {
  expect_bad_document("[material]\nee = 0.8\n", {"material.ee", "material.e", "known"});
  expect_bad_document("[shaker]\ngama = 3.0\n", {"shaker.gama", "shaker.gamma"});
  expect_input_error([] { Config().set("md.boxwidth=20"); }, {"md.boxwidth", "md.box_width"});
}

TEST(Config, RejectsUnknownSection) {
  expect_bad_document("[materials]\ne = 0.8\n", {"materials.e", "no such section"});
  expect_bad_document("gamma = 3.0\n", {"gamma", "no such section"});
  expect_input_error([] { Config().set("solver.e=0.8"); }, {"solver.e", "no such section"});
}

TEST(Config, RejectsWrongTypes) {
  // A string for a number.
  expect_bad_document("[shaker]\ngamma = \"three\"\n",
                      {"shaker.gamma", "\"three\"", "wrong type", "a real number"});
  // A float for an integer.
  expect_bad_document("[layer]\nparticles = 3937.5\n",
                      {"layer.particles", "3937.5", "wrong type", "an integer"});
  // A boolean, a list and a table where a number is expected.
  expect_bad_document("[material]\ne = true\n", {"material.e", "true", "a real number"});
  expect_bad_document("[material]\ne = [0.9]\n", {"material.e", "a real number"});
  expect_bad_document("[material.e]\nx = 1.0\n", {"material.e.x"});
  // A number for a string.
  expect_bad_document("[material]\nrestitution = 1\n", {"material.restitution", "1", "a string"});
}

TEST(Config, RejectsOutOfRangeValuesNamingTheRange) {
  expect_bad_document("[material]\ne = 1.1\n", {"material.e", "1.1", "0 <= value <= 1"});
  expect_bad_document("[material]\ne = -0.1\n", {"material.e", "-0.1", "0 <= value <= 1"});
  expect_bad_document("[layer]\nparticles = -5\n", {"layer.particles", "-5", "1 <= value"});
  expect_bad_document("[layer]\nparticles = 0\n", {"layer.particles", "0", "1 <= value"});
  expect_bad_document("[shaker]\ngamma = -1.0\n", {"shaker.gamma", "-1.0", "0 < value"});
  expect_bad_document("[shaker]\ngamma = 0.0\n", {"shaker.gamma", "0.0", "0 < value"});
  expect_bad_document("[shaker]\ngamma = nan\n", {"shaker.gamma", "nan", "0 < value"});
  expect_bad_document("[shaker]\nfrequency = inf\n", {"shaker.frequency", "inf"});
  // A box narrower than a particle (sigma = 1).
  expect_bad_document("[md]\nbox_width = 0.5\n", {"md.box_width", "0.5", "1 < value"});
  expect_bad_document("[md]\nbox_width = 1.0\n", {"md.box_width", "1.0", "1 < value"});
  expect_bad_document("[continuum]\nbox_width = 0.5\n",
                      {"continuum.box_width", "0.5", "1 < value"});
  expect_bad_document("[continuum]\ninitial_volume_fraction = 0.65\n",
                      {"continuum.initial_volume_fraction", "0.65", "value < 0.65"});
  // The ends of closed ranges are accepted.
  EXPECT_NO_THROW(Config::from_toml("[material]\ne = 1.0\n", "case.toml"));
  EXPECT_NO_THROW(Config::from_toml("[material]\ne = 0.0\n", "case.toml"));
  EXPECT_EQ(Config::from_toml("[layer]\nparticles = 1\n", "case.toml").integer("layer.particles"),
            1);
}

TEST(Config, RejectsChoicesThatAreNotAllowed) {
  expect_bad_document("[material]\nrestitution = \"elastic\"\n",
                      {"material.restitution", "elastic", "constant, velocity_dependent"});
  expect_bad_document("[continuum]\ntransport = \"exact\"\n",
                      {"continuum.transport", "exact", "paper, full"});
  expect_bad_document("[run]\nprotocol = \"Periodic\"\n",
                      {"run.protocol", "Periodic", "periodic, single_shock"});
}

TEST(Config, RejectsMalformedToml) {
  expect_bad_document("[shaker\ngamma = 3.0\n", {"case.toml", "not valid TOML"});
  expect_bad_document("[shaker]\ngamma = 3.0\ngamma = 2.0\n", {"case.toml", "not valid TOML"});
  expect_bad_document("[shaker]\ngamma = 3.0.0\n", {"case.toml", "not valid TOML"});
  expect_bad_document("[shaker]\ngamma =\n", {"case.toml", "not valid TOML"});
}

TEST(Config, FileErrorsNameTheFile) {
  const shaker::testing::TemporaryDirectory dir;
  expect_input_error([&] { Config::load(dir / "missing.toml", {}); },
                     {"missing.toml", "cannot open"});
  write_file(dir / "bad.toml", "[material]\ne = 1.5\n");
  expect_input_error([&] { Config::load(dir / "bad.toml", {}); },
                     {"bad.toml", "material.e", "1.5", "0 <= value <= 1"});
}

TEST(Config, RejectsMalformedOverrides) {
  expect_input_error([] { Config().set("shaker.gamma"); }, {"shaker.gamma", "key=value"});
  expect_input_error([] { Config().set("=3.0"); }, {"=3.0", "key=value"});
  expect_input_error([] { Config().set("shaker.gamma=abc"); },
                     {"shaker.gamma", "abc", "a real number"});
  expect_input_error([] { Config().set("shaker.gamma="); }, {"shaker.gamma", "a real number"});
  expect_input_error([] { Config().set("shaker.gamma=3.0x"); }, {"shaker.gamma", "3.0x"});
  expect_input_error([] { Config().set("layer.particles=12.5"); },
                     {"layer.particles", "12.5", "an integer"});
  expect_input_error([] { Config().set("material.e=2"); }, {"material.e", "2", "0 <= value <= 1"});
  expect_input_error([] { Config().set("md.box_width=0.5"); },
                     {"md.box_width", "0.5", "1 < value"});
  expect_input_error([] { Config().set("material.restitution=elastic"); },
                     {"material.restitution", "elastic", "constant, velocity_dependent"});
}

TEST(Config, OverridesApplyInOrderAfterTheFile) {
  const shaker::testing::TemporaryDirectory dir;
  write_file(dir / "case.toml", "[material]\ne = 0.8\n[layer]\nparticles = 1969\n");
  const Config from_file = Config::load(dir / "case.toml", {});
  EXPECT_EQ(from_file.real("material.e"), 0.8);
  EXPECT_EQ(from_file.integer("layer.particles"), 1969);
  EXPECT_EQ(from_file.real("shaker.gamma"), 3.0);  // untouched keys keep their defaults

  const Config c =
      Config::load(dir / "case.toml", {"material.e=0.7", "shaker.gamma=4", "material.e=0.75",
                                       "case.name=a=b", "material.restitution=velocity_dependent"});
  EXPECT_EQ(c.real("material.e"), 0.75);   // the last override wins over the file
  EXPECT_EQ(c.real("shaker.gamma"), 4.0);  // an integer literal is read as a real
  EXPECT_EQ(c.text("case.name"), "a=b");   // only the first '=' separates key and value
  EXPECT_EQ(c.text("material.restitution"), "velocity_dependent");
  EXPECT_EQ(c.integer("layer.particles"), 1969);
  // Overrides without a file.
  EXPECT_EQ(Config::load({}, {"run.seed=42"}).integer("run.seed"), 42);
  EXPECT_EQ(shaker::CaseParameters::from(c).restitution.kind,
            shaker::Restitution::Kind::velocity_dependent);
}

// ---- round trip and hash ----------------------------------------------------------------------

void expect_identical_values(const Config& a, const Config& b) {
  for (const auto& spec : shaker::config::schema()) {
    SCOPED_TRACE(spec.key);
    switch (spec.kind) {
      case shaker::config::Kind::real:
        EXPECT_EQ(std::bit_cast<std::uint64_t>(a.real(spec.key)),
                  std::bit_cast<std::uint64_t>(b.real(spec.key)));
        break;
      case shaker::config::Kind::integer:
        EXPECT_EQ(a.integer(spec.key), b.integer(spec.key));
        break;
      case shaker::config::Kind::boolean:
        EXPECT_EQ(a.boolean(spec.key), b.boolean(spec.key));
        break;
      case shaker::config::Kind::text:
        EXPECT_EQ(a.text(spec.key), b.text(spec.key));
        break;
      case shaker::config::Kind::real_list:
        EXPECT_EQ(a.real_list(spec.key), b.real_list(spec.key));
        break;
    }
  }
}

TEST(Config, ToTomlRoundTripsToIdenticalText) {
  std::vector<Config> cases(1);  // the defaults
  Config awkward;
  awkward.set_value("material.e", 0.1 + 0.2);  // 0.30000000000000004: needs 17 digits
  awkward.set_value("shaker.frequency", 1.0 / 3.0);
  awkward.set_value("md.tc", 1e-300);
  awkward.set_value("shaker.gamma", 7.0);
  awkward.set_value("run.seed", std::int64_t{9000000000000000});
  awkward.set("run.switch_phase=-0.9999999999999999");
  cases.push_back(awkward);
  Config quoted;
  quoted.set_value("case.name", std::string("say \"hi\" \\ back\\slash\ttab"));
  quoted.set_value("run.output", std::string("C:\\runs\\base case.h5"));
  cases.push_back(quoted);
  for (const auto& c : cases) {
    const std::string text = c.to_toml();
    SCOPED_TRACE(text);
    Config back;
    ASSERT_NO_THROW(back = Config::from_toml(text, "round-trip")) << "to_toml() is not valid TOML";
    EXPECT_EQ(back.to_toml(), text);
    expect_identical_values(back, c);
  }
}

std::string fnv1a_64(const std::string& text) {
  std::uint64_t h = 1469598103934665603ULL;
  for (unsigned char c : text) h = (h ^ c) * 1099511628211ULL;
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(h));
  return hex;
}

TEST(Config, HashIsStableAndSensitive) {
  const Config defaults;
  // Stable across processes and platforms: FNV-1a of the canonical text, not std::hash.
  EXPECT_EQ(defaults.hash(), fnv1a_64(defaults.to_toml()));
  EXPECT_EQ(defaults.hash().size(), 16u);
  EXPECT_EQ(Config().hash(), defaults.hash());
  EXPECT_EQ(Config::from_toml(defaults.to_toml(), "copy").hash(), defaults.hash());
  // Writing a default explicitly does not change the effective configuration.
  EXPECT_EQ(Config::from_toml("[material]\ne = 0.9\n", "explicit").hash(), defaults.hash());
  // Any change, however small, changes the hash.
  Config changed;
  changed.set_value("material.e", std::nextafter(0.9, 1.0));
  EXPECT_NE(changed.hash(), defaults.hash());
  Config renamed;
  renamed.set("run.output=other.h5");
  EXPECT_NE(renamed.hash(), defaults.hash());
  Config seeded;
  seeded.set("run.seed=2");
  EXPECT_NE(seeded.hash(), defaults.hash());
}

}  // namespace
