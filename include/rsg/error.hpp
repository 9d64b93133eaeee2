// The one exception hierarchy of rsg's setup code (CONTRIBUTING.md, "Errors"): opening sockets,
// creating DDS entities, loading profiles and views, reading a configuration. The per-frame path
// and the wire layer never throw; they return result types.
//
// Whose fault it is decides what an executable does about it, in one place (the tools' main
// skeleton): an InputError is the user's (a bad flag, file, profile, view or address: exit 2),
// an EnvironmentError the machine's at run time (a socket, DDS, the file system: exit 1).
#pragma once

#include <stdexcept>
#include <string>

namespace rsg {

/// Base of everything rsg throws. `what()` is one line naming the thing and the problem,
/// e.g. `gateway.yaml:4: 'x' is not an integer`.
class Error : public std::runtime_error {
 public:
  enum class Kind {
    kInput,        ///< the user's input is wrong: fix the flag, file, profile, view or address
    kEnvironment,  ///< the environment refused at run time: a socket, DDS, the file system
  };

  Kind kind() const noexcept { return kind_; }

 protected:
  Error(Kind kind, const std::string& message) : std::runtime_error(message), kind_(kind) {}

 private:
  Kind kind_;
};

/// The user's input is wrong; nothing was started because of it.
class InputError : public Error {
 public:
  explicit InputError(const std::string& message) : Error(Kind::kInput, message) {}
};

/// The environment refused: a socket could not be bound, Fast DDS refused an entity, a file could
/// not be written.
class EnvironmentError : public Error {
 public:
  explicit EnvironmentError(const std::string& message) : Error(Kind::kEnvironment, message) {}
};

}  // namespace rsg
