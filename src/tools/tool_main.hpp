// The exit statuses and error reporting every rsg executable shares (the tools and rsg_gateway), so
// that scripts can tell a usage mistake (2) from a failure at run time (1) the same way for all.
#pragma once

#include <CLI/CLI.hpp>
#include <exception>
#include <iostream>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "rsg/error.hpp"

namespace rsg::tools {

/// Exit statuses (CONTRIBUTING.md): done, a failure at run time, a usage or input error.
inline constexpr int kExitOk = 0;
inline constexpr int kExitFailure = 1;
inline constexpr int kExitUsage = 2;

/// Parses the command line; returns the exit status when the tool must stop here (--help: 0, a
/// parse error: 2, with CLI11's message), or nothing to go on.
inline std::optional<int> parse_command_line(CLI::App& app, int argc, char** argv) {
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& error) {
    return app.exit(error) == 0 ? kExitOk : kExitUsage;
  }
  return std::nullopt;
}

/// The one mapping from what setup code throws to an exit status (CONTRIBUTING.md, "Errors"):
/// the user's input (rsg::InputError: a bad file, profile, view or address) is 2, everything else
/// (rsg::EnvironmentError: DDS, sockets, files; or anything unexpected) is 1.
inline int exit_status_of(const std::exception& error) noexcept {
  const auto* rsg_error = dynamic_cast<const rsg::Error*>(&error);
  return rsg_error != nullptr && rsg_error->kind() == rsg::Error::Kind::kInput ? kExitUsage : kExitFailure;
}

/// Runs `body` (which returns the exit status) and turns what it throws into "<tool>: <what>" on
/// stderr and exit_status_of() it.
template <class Body>
int run_reporting_errors(std::string_view tool, Body&& body) {
  try {
    return std::forward<Body>(body)();
  } catch (const std::exception& error) {
    std::cerr << tool << ": " << error.what() << '\n';
    return exit_status_of(error);
  }
}

}  // namespace rsg::tools
