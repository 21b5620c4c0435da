#pragma once
// The kinds of failure the programs distinguish: bad input from the user (exit code 2,
// nothing written), a run the physics stopped (exit code 3), and a model evaluated outside its
// domain (a bug or a blown-up state).
#include <stdexcept>
#include <string>

namespace shaker {

/// Configuration, checkpoint or command-line input that is invalid. The message names the
/// offending item, its value and the allowed range.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Inelastic collapse started and no guard is on: the input was valid and the program worked,
/// but the model cannot go on (exit code 3, so that a study tells it from a failure by the
/// code alone).
class CollapseError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The exit code of a run stopped by CollapseError.
inline constexpr int collapse_exit_code = 3;

/// A constitutive function called outside its domain (nu <= 0, nu >= nu_max, T < 0, ...).
class DomainError : public std::domain_error {
 public:
  using std::domain_error::domain_error;
};

}  // namespace shaker
