// The versions rsg_gateway reports: `--version`, the metrics' rsg_build_info.
#pragma once

#include <string_view>

namespace rsg::gateway {

/// rsg's version: the CMake project version (CMakeLists.txt's `project(rsg VERSION ...)`).
std::string_view rsg_version();

/// The version of the Fast DDS rsg was built against (its CMake package's version).
std::string_view fastdds_version();

}  // namespace rsg::gateway
