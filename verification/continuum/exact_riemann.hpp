#pragma once
// Exact solution of the Riemann problem of the Euler equations for an ideal gas (here
// gamma = 5/3, the dilute limit of the model), after Toro, "Riemann Solvers and Numerical
// Methods for Fluid Dynamics", ch. 4: Newton iteration on the star pressure, then sampling
// of the self-similar solution. Independent of the solver's code.
#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace shaker::continuum::testing {

struct GasState {
  double rho, u, p;
};

class ExactRiemann {
 public:
  ExactRiemann(GasState left, GasState right, double gamma = 5.0 / 3.0)
      : L_(left), R_(right), g_(gamma) {
    cL_ = std::sqrt(g_ * L_.p / L_.rho);
    cR_ = std::sqrt(g_ * R_.p / R_.rho);
    solve_star();
  }
  double star_pressure() const { return p_star_; }
  double star_velocity() const { return u_star_; }

  /// The state at similarity coordinate s = (x - x0) / t.
  GasState sample(double s) const {
    const double g = g_;
    if (s <= u_star_) {
      const GasState& K = L_;
      const double c = cL_;
      if (p_star_ > K.p) {  // left shock
        const double ratio = p_star_ / K.p;
        const double speed = K.u - c * std::sqrt((g + 1) / (2 * g) * ratio + (g - 1) / (2 * g));
        if (s <= speed) return K;
        const double rho = K.rho * (ratio + (g - 1) / (g + 1)) / ((g - 1) / (g + 1) * ratio + 1);
        return {rho, u_star_, p_star_};
      }
      const double head = K.u - c;
      const double c_star = c * std::pow(p_star_ / K.p, (g - 1) / (2 * g));
      const double tail = u_star_ - c_star;
      if (s <= head) return K;
      if (s >= tail) return {K.rho * std::pow(p_star_ / K.p, 1 / g), u_star_, p_star_};
      const double factor = 2 / (g + 1) + (g - 1) / ((g + 1) * c) * (K.u - s);
      return {K.rho * std::pow(factor, 2 / (g - 1)), 2 / (g + 1) * (c + (g - 1) / 2 * K.u + s),
              K.p * std::pow(factor, 2 * g / (g - 1))};
    }
    const GasState& K = R_;
    const double c = cR_;
    if (p_star_ > K.p) {  // right shock
      const double ratio = p_star_ / K.p;
      const double speed = K.u + c * std::sqrt((g + 1) / (2 * g) * ratio + (g - 1) / (2 * g));
      if (s >= speed) return K;
      const double rho = K.rho * (ratio + (g - 1) / (g + 1)) / ((g - 1) / (g + 1) * ratio + 1);
      return {rho, u_star_, p_star_};
    }
    const double head = K.u + c;
    const double c_star = c * std::pow(p_star_ / K.p, (g - 1) / (2 * g));
    const double tail = u_star_ + c_star;
    if (s >= head) return K;
    if (s <= tail) return {K.rho * std::pow(p_star_ / K.p, 1 / g), u_star_, p_star_};
    const double factor = 2 / (g + 1) - (g - 1) / ((g + 1) * c) * (K.u - s);
    return {K.rho * std::pow(factor, 2 / (g - 1)), 2 / (g + 1) * (-c + (g - 1) / 2 * K.u + s),
            K.p * std::pow(factor, 2 * g / (g - 1))};
  }

 private:
  // Pressure function f_K(p) and its derivative (Toro eq. 4.6-4.7).
  void pressure_function(double p, const GasState& K, double c, double& f, double& df) const {
    const double g = g_;
    if (p > K.p) {
      const double A = 2 / ((g + 1) * K.rho), B = (g - 1) / (g + 1) * K.p;
      const double q = std::sqrt(A / (p + B));
      f = (p - K.p) * q;
      df = q * (1 - 0.5 * (p - K.p) / (B + p));
    } else {
      f = 2 * c / (g - 1) * (std::pow(p / K.p, (g - 1) / (2 * g)) - 1);
      df = 1 / (K.rho * c) * std::pow(p / K.p, -(g + 1) / (2 * g));
    }
  }
  void solve_star() {
    double p = std::max(1e-12, 0.5 * (L_.p + R_.p));
    for (int it = 0; it < 200; ++it) {
      double fL, dfL, fR, dfR;
      pressure_function(p, L_, cL_, fL, dfL);
      pressure_function(p, R_, cR_, fR, dfR);
      const double change = (fL + fR + R_.u - L_.u) / (dfL + dfR);
      const double next = std::max(1e-14, p - change);
      if (std::abs(next - p) < 1e-15 * (next + p)) {
        p = next;
        break;
      }
      p = next;
    }
    double fL, dfL, fR, dfR;
    pressure_function(p, L_, cL_, fL, dfL);
    pressure_function(p, R_, cR_, fR, dfR);
    p_star_ = p;
    u_star_ = 0.5 * (L_.u + R_.u) + 0.5 * (fR - fL);
  }

  GasState L_, R_;
  double g_, cL_, cR_, p_star_ = 0, u_star_ = 0;
};

}  // namespace shaker::continuum::testing
