// errno in the gateway's messages: the text and the symbolic name, so that an operator can search
// for either.
#pragma once

#include <cstring>
#include <string>

namespace rsg::gateway {

/// errno as "No such file or directory (ENOENT)".
inline std::string errno_text(int error) {
  const char* name = ::strerrorname_np(error);
  return std::string(std::strerror(error)) + " (" + (name != nullptr ? name : std::to_string(error)) + ")";
}

}  // namespace rsg::gateway
