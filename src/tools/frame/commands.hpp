// The subcommands of `rsg_frame`, as plain functions from an input stream to output streams, so
// that argument parsing (main.cpp) and the conversions themselves stay apart. Each returns the
// process's exit status (exit_status.hpp): kExitOk when everything converted (`decode --hex-lines`:
// the input was readable), kExitFailure for an invalid frame, malformed JSON or hex, or an I/O failure.
#pragma once

#include <cstdint>
#include <iosfwd>

#include "app/exit_status.hpp"
#include "rsg/wire/selection.hpp"

namespace rsg::tools::frame {

/// How frames are written: raw bytes back to back, or one lowercase hex line per frame.
enum class FrameFormat { kBinary, kHexLines };

struct Streams {
  std::istream& in;
  std::ostream& out;
  std::ostream& err;
};

/// The whole input is one binary frame: prints its canonical JSON, or `error: <category>: <message>`.
int decode_binary(Streams streams);

/// One hex frame per line: prints one line per non-blank input line, canonical JSON or
/// `{"error":"<category>","message":"..."}` (category `bad_hex` when the line is not hex).
int decode_hex_lines(Streams streams);

/// One canonical JSON object per line: writes one frame per object. Stops at the first line that
/// does not parse or cannot be encoded, reporting `error: line N: <reason>`; the frames of the
/// lines before it have already been written.
int encode_json_lines(Streams streams, FrameFormat format);

/// Writes the spec's selection request (gateway -> robot) for `selection`.
int write_selection_request(Streams streams, std::uint8_t packet_number, const wire::Selection& selection,
                            FrameFormat format);

}  // namespace rsg::tools::frame
