#include <gtest/gtest.h>
#include "common/granular_model.hpp"
TEST(GranularModel, Placeholder) { EXPECT_NEAR(shaker::model::g0(0.3), 1.0 / (1.0 - std::pow(0.3 / 0.65, 4.0 / 3.0 * 0.65)), 1e-15); }
