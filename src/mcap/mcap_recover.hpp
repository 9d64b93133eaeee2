// Recovery of a recording whose writer died (SIGKILL, a crash, a power loss): what a front-to-back
// scan reads of it (every schema and channel, the messages of every whole chunk) is written again
// as a finished, indexed MCAP file, with the original header. The damaged file is left as it is.
//
//   const auto result = rsg::mcap::recover(MappedFile("killed.mcap").bytes(), "fixed.mcap", {});
//
// What the copy holds is exactly what rsg_replay plays of the damaged file; the records are
// chunked and compressed anew (WriterOptions), so byte offsets differ, the messages do not.
#pragma once

#include <filesystem>
#include <span>

#include "mcap/mcap_reader.hpp"
#include "mcap/mcap_writer.hpp"

namespace rsg::mcap {

struct RecoverResult {
  ScanResult scan;               ///< how far the damaged file read (truncated: a killed writer's file)
  WriterTotals written;          ///< what the new file holds
  std::uint64_t unreadable = 0;  ///< messages on a channel the file never described (left out)
};

/// Writes what `damaged` holds to `out` (profile and library from its header; `options` for the
/// rest).
/// @throws WriteError (an rsg::EnvironmentError) when `out` cannot be written, rsg::InputError when
/// `damaged` has no header (not MCAP).
RecoverResult recover(std::span<const std::uint8_t> damaged, const std::filesystem::path& out,
                      WriterOptions options);

}  // namespace rsg::mcap
