// The exit statuses of every rsg executable (CONTRIBUTING.md, "Errors"), for code that decides one
// without the rest of the main() skeleton (tool_main.hpp), such as rsg_frame's conversions.
#pragma once

namespace rsg::app {

/// Done: --count reached, --help, SIGINT or SIGTERM.
inline constexpr int kExitOk = 0;
/// A failure at run time: rsg::EnvironmentError or anything unexpected (rsg_frame: an invalid frame).
inline constexpr int kExitFailure = 1;
/// A usage error: bad flags, or an rsg::InputError (file, profile, view, address).
inline constexpr int kExitUsage = 2;

}  // namespace rsg::app
