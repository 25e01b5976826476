// Errors that carry their context to the user: the deck file, line and key for bad
// input (exit status 2), the element or particle and the time for a physically failed
// run (exit status 3).
#pragma once

#include <stdexcept>
#include <string>

namespace anvil {

// Where a value came from: a file and a 1-based line (0 when unknown) and the dotted
// key path inside the deck (`materials.copper.density`).
struct SourceLocation {
  std::string file;
  int line = 0;
  std::string key;

  std::string str() const; // "deck.yaml:12: materials.copper.density"
};

// Bad input: deck, mesh file, command-line arguments. The program exits with status 2.
class InputError : public std::runtime_error {
public:
  InputError(const SourceLocation& where, const std::string& message);
  explicit InputError(const std::string& message);
  const SourceLocation& where() const { return where_; }

private:
  SourceLocation where_;
};

// A run that failed physically: inverted element, non-finite state, collapsed time step.
// `entity` names what failed ("element 1234 (part bar)"); the program exits with status 3.
class PhysicsError : public std::runtime_error {
public:
  PhysicsError(const std::string& entity, double time, const std::string& message);
  const std::string& entity() const { return entity_; }
  double time() const { return time_; }

private:
  std::string entity_;
  double time_;
};

inline constexpr int exit_ok = 0;
inline constexpr int exit_bad_input = 2;
inline constexpr int exit_physics = 3;

} // namespace anvil
