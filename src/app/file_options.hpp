// Checks of the file paths the tools take, as CLI11 validators: a file a tool will write is refused
// when the command line is parsed (exit 2, "--out: ..."), not after the tool has run for a while.
#pragma once

#include <unistd.h>

#include <CLI/CLI.hpp>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <string>

namespace rsg::app {

/// A file the tool will create or replace: its directory exists and can be written to.
inline CLI::Validator writable_file() {
  return CLI::Validator(
      [](const std::string& path) {
        if (path.empty()) return std::string("an empty path");
        const std::filesystem::path parent = std::filesystem::path(path).parent_path();
        const std::string dir = parent.empty() ? std::string(".") : parent.string();
        if (::access(dir.c_str(), W_OK) != 0)
          return "cannot write '" + path + "': directory '" + dir + "': " + std::strerror(errno);
        std::error_code error;
        if (std::filesystem::is_directory(path, error)) return "'" + path + "' is a directory";
        return std::string();
      },
      "", "");
}

}  // namespace rsg::app
