// Bad input through the `shaker` program: exit code 2, a message naming the key, and nothing
// written under the output name.
#include <cstdlib>
#include <fstream>

#include "support.hpp"

namespace shaker::continuum::testing {
namespace {

struct BadCase {
  const char* name;
  const char* setting;
  const char* key_in_message;
};

class BadInput : public ::testing::TestWithParam<BadCase> {};

TEST_P(BadInput, ExitsWithCodeTwoAndWritesNothing) {
  const BadCase& bad = GetParam();
  const auto dir = test_directory();
  const auto output = dir / "run.h5";
  const auto log = dir / "stderr.txt";
  const std::string command = std::string(SHAKER_BINARY) + " continuum \"\" --set run.output=" +
                              output.string() + " --set " + bad.setting + " --set run.transient_cycles=0"
                              " --set run.sampled_cycles=1 2> " + log.string() + " > /dev/null";
  const int status = std::system(command.c_str());
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 2) << bad.setting;
  EXPECT_FALSE(std::filesystem::exists(output));
  std::size_t files = 0;
  for ([[maybe_unused]] const auto& entry : std::filesystem::directory_iterator(dir)) ++files;
  EXPECT_EQ(files, 1u) << "only the captured stderr may exist";
  std::ifstream in(log);
  const std::string message((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(message.find(bad.key_in_message), std::string::npos) << message;
}

INSTANTIATE_TEST_SUITE_P(
    Continuum, BadInput,
    ::testing::Values(BadCase{"resolution", "continuum.cell_size=0.3", "continuum.cell_size"},
                      BadCase{"resolution3d", "continuum.dimension=3 --set continuum.box_width=11.2 --set continuum.cell_size=0.5", "continuum.box_width"},
                      BadCase{"ceiling", "continuum.ceiling=8", "continuum.ceiling"},
                      BadCase{"nu_max", "continuum.initial_volume_fraction=0.65", "continuum.initial_volume_fraction"},
                      BadCase{"transport", "continuum.transport=partial", "continuum.transport"},
                      BadCase{"limiter", "continuum.limiter=superbee", "continuum.limiter"},
                      BadCase{"stages", "continuum.integrator_stages=11", "continuum.integrator_stages"},
                      BadCase{"stages_order3", "continuum.integrator_order=3 --set continuum.integrator_stages=4",
                              "continuum.integrator_stages"},
                      BadCase{"diffusion", "continuum.diffusion_integrator=crank_nicolson",
                              "continuum.diffusion_integrator"}),
    [](const auto& param_info) { return std::string(param_info.param.name); });

}  // namespace
}  // namespace shaker::continuum::testing
