#pragma once
// The two kinds of failure the programs distinguish: bad input from the user (exit code 2,
// nothing written) and a model evaluated outside its domain (a bug or a blown-up state).
#include <stdexcept>
#include <string>

namespace shaker {

/// Configuration, checkpoint or command-line input that is invalid. The message names the
/// offending item, its value and the allowed range.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A constitutive function called outside its domain (nu <= 0, nu >= nu_max, T < 0, ...).
class DomainError : public std::domain_error {
 public:
  using std::domain_error::domain_error;
};

}  // namespace shaker
