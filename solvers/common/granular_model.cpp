#include "common/granular_model.hpp"

#include <fmt/format.h>

#include "common/restitution.hpp"

namespace shaker {
namespace model::detail {
void domain_failure(const char* function, const char* what, double value, const char* allowed) {
  throw DomainError(fmt::format("{}: {} = {} is outside the domain ({})", function, what, value,
                                allowed));
}
}  // namespace model::detail

std::string model::to_string(Transport transport) {
  return transport == Transport::paper ? "paper" : "full";
}

model::Transport model::transport_from_string(const std::string& name) {
  if (name == "paper") return Transport::paper;
  if (name == "full") return Transport::full;
  throw InputError(fmt::format("unknown transport variant '{}' (allowed: paper, full)", name));
}

std::string to_string(Restitution::Kind kind) {
  return kind == Restitution::Kind::constant ? "constant" : "velocity_dependent";
}

Restitution::Kind restitution_kind_from_string(const std::string& name) {
  if (name == "constant") return Restitution::Kind::constant;
  if (name == "velocity_dependent") return Restitution::Kind::velocity_dependent;
  throw InputError(fmt::format(
      "unknown restitution model '{}' (allowed: constant, velocity_dependent)", name));
}

}  // namespace shaker
