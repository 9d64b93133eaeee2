// The exit statuses and error reporting every rsg command-line tool shares, so that scripts can
// tell a usage mistake (2) from a failure at run time (1) the same way for all of them.
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

#include "rsg/dds/profiles.hpp"
#include "rsg/dds/views.hpp"

namespace rsg::tools {

enum ExitCode : int { kExitOk = 0, kExitFailure = 1, kExitUsage = 2 };

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

/// Loads the XML profiles the tool was given (none: rsg's own); a missing or malformed file, or no
/// such participant profile, is a usage error: returns 2 after saying why, or nothing to go on.
inline std::optional<int> load_profiles(std::string_view tool, const std::vector<std::string>& files_or_dirs,
                                        const std::string& participant_profile) {
  try {
    rsg::dds::load_profiles(files_or_dirs, participant_profile);
  } catch (const std::exception& error) {
    std::cerr << tool << ": " << error.what() << '\n';
    return kExitUsage;
  }
  return std::nullopt;
}

/// Runs `body` (which returns the exit status) and turns what it throws into "<tool>: <what>" on
/// stderr and an exit status: 2 for what the user asked wrongly but could only be found out once
/// running (an unknown or malformed view or profile: rsg::dds::ViewError; a bad address:
/// std::invalid_argument), 1 for everything else (DDS, sockets, files).
template <class Body>
int run_reporting_errors(std::string_view tool, Body&& body) {
  try {
    return std::forward<Body>(body)();
  } catch (const rsg::dds::ViewError& error) {
    std::cerr << tool << ": " << error.what() << '\n';
    return kExitUsage;
  } catch (const std::invalid_argument& error) {
    std::cerr << tool << ": " << error.what() << '\n';
    return kExitUsage;
  } catch (const std::exception& error) {
    std::cerr << tool << ": " << error.what() << '\n';
    return kExitFailure;
  }
}

}  // namespace rsg::tools
