#include "anvil/core/error.hpp"

#include <fmt/format.h>

namespace anvil {

std::string SourceLocation::str() const {
  std::string s = file.empty() ? std::string("<input>") : file;
  if (line > 0) s += fmt::format(":{}", line);
  if (!key.empty()) s += ": " + key;
  return s;
}

InputError::InputError(const SourceLocation& where, const std::string& message)
    : std::runtime_error(where.str() + ": " + message), where_(where) {}

InputError::InputError(const std::string& message) : std::runtime_error(message) {}

PhysicsError::PhysicsError(const std::string& entity, double time, const std::string& message)
    : std::runtime_error(fmt::format("{} at time {:.9g}: {}", entity, time, message)),
      entity_(entity), time_(time) {}

} // namespace anvil
