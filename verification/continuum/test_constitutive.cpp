// The fused closure (model::constitutive_values, G evaluated once) against the individual
// constitutive functions it replaces in the solver: equal to 1e-14 relative over the whole
// range of volume fraction (dilute to near nu_max), temperature, e and both transport variants.
#include <gtest/gtest.h>

#include <cmath>

#include "common/granular_model.hpp"
#include "support/convergence.hpp"

namespace shaker::model {
namespace {

using shaker::convergence::relative_error;

TEST(ConstitutiveValues, EqualTheIndividualFunctions) {
  double worst = 0.0;
  for (double nu : {1e-8, 1e-4, 0.01, 0.1, 0.3, 0.5, 0.6, 0.64, 0.6499})
    for (double T : {1e-10, 1e-4, 0.3, 7.0})
      for (double e : {0.0, 0.5, 0.9, 1.0})
        for (Transport transport : {Transport::paper, Transport::full}) {
          const double n = nu / volume_fraction(1.0);
          const ConstitutiveValues<double> m = constitutive_values(n, T, e, transport);
          const double nu_n = volume_fraction(n);
          const double pairs[][2] = {
              {m.G, G(nu_n)},
              {m.chi, chi(nu_n, e)},
              {m.pressure, pressure(n, T, e)},
              {m.sound_speed, sound_speed(nu_n, T, e)},
              {m.collisional_loss, collisional_loss(n, T, e)},
              {m.bulk_viscosity, bulk_viscosity(n, T)},
              {m.shear_viscosity, shear_viscosity(n, T, transport)},
              {m.thermal_conductivity, thermal_conductivity(n, T, transport)}};
          for (const auto& pair : pairs) {
            if (pair[1] == 0.0) {
              EXPECT_EQ(pair[0], 0.0);  // e = 1: no collisional loss
              continue;
            }
            worst = std::max(worst, relative_error(pair[0], pair[1]));
          }
        }
  std::printf("largest relative difference fused vs individual: %.3e\n", worst);
  EXPECT_LE(worst, 1e-14);
}

TEST(ConstitutiveValues, ThrowsOutsideTheDomain) {
  EXPECT_THROW(constitutive_values(nu_max / volume_fraction(1.0), 1.0, 0.9, Transport::paper),
               DomainError);
  EXPECT_THROW(constitutive_values(0.1, -1e-3, 0.9, Transport::paper), DomainError);
  EXPECT_THROW(constitutive_values(0.1, 1.0, 1.1, Transport::full), DomainError);
}

}  // namespace
}  // namespace shaker::model
