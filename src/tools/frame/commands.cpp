#include "tools/frame/commands.hpp"

#include <array>
#include <cstdio>
#include <istream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <optional>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

#include "rsg/wire/field_table.hpp"
#include "rsg/wire/frame.hpp"
#include "rsg/wire/hex.hpp"
#include "rsg/wire/json.hpp"
#include "rsg/wire/state_values.hpp"
#include "wire/internal/text.hpp"

namespace rsg::tools::frame {
namespace {

using app::kExitFailure;
using app::kExitOk;

/// Calls `on_line(number, text)` for every line that is not blank; `number` counts from 1 and
/// includes blank lines, so that it matches what an editor shows. Stops when `on_line` is false.
template <class OnLine>
void for_each_nonblank_line(std::istream& in, OnLine&& on_line) {
  std::size_t number = 0;
  for (std::string line; std::getline(in, line);) {
    ++number;
    const std::string_view text = wire::internal::trim(line);
    if (!text.empty() && !on_line(number, text)) return;
  }
}

// A selection request read as a state frame fails length_mismatch, on purpose (docs/protocol.md):
// the bytes a user most likely pasted from the gateway's side. What it asks for, when it is one.
std::optional<nlohmann::ordered_json> selection_request_of(std::span<const std::uint8_t> bytes) {
  const wire::SelectionRequestResult request = wire::decode_selection_request(bytes);
  if (!request) return std::nullopt;
  nlohmann::ordered_json fields = nlohmann::ordered_json::array();
  for (const wire::FieldInfo& field : wire::kFields)
    if (request.selection.contains(field.id())) fields.push_back(field.name);
  return nlohmann::ordered_json{{"packet_number", request.packet_number},
                                {"group_select", request.selection.group_select},
                                {"data_select", request.selection.data_select},
                                {"fields", std::move(fields)}};
}

std::string error_line(std::string_view category, std::string_view message,
                       std::optional<nlohmann::ordered_json> request = std::nullopt) {
  // ordered_json keeps "error" first; replace, not throw, on bytes that are not UTF-8.
  nlohmann::ordered_json line = {{"error", category}, {"message", message}};
  if (request) line["selection_request"] = std::move(*request);
  return line.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

constexpr std::string_view kRequestNote =
    "these bytes are a selection request (gateway -> robot), not a state frame (robot -> gateway): ";

void write_frame(std::ostream& out, std::span<const std::uint8_t> frame, FrameFormat format) {
  if (format == FrameFormat::kHexLines) {
    out << wire::to_hex(frame) << '\n';
  } else {
    out.write(reinterpret_cast<const char*>(frame.data()), static_cast<std::streamsize>(frame.size()));
  }
}

/// The final status once everything has been written: a write that failed (full disk, closed pipe)
/// must not look like success.
int finish(Streams streams, int status) {
  streams.out.flush();
  if (!streams.out) {
    streams.err << "error: cannot write the output\n";
    return kExitFailure;
  }
  if (streams.in.bad()) {
    streams.err << "error: cannot read the input\n";
    return kExitFailure;
  }
  return status;
}

}  // namespace

int decode_binary(Streams streams) {
  const std::vector<std::uint8_t> bytes(std::istreambuf_iterator<char>(streams.in), {});
  if (streams.in.bad()) return finish(streams, kExitFailure);
  const wire::DecodeResult result = wire::decode(bytes);
  if (!result) {
    streams.err << "error: " << wire::to_string(result.error().category()) << ": " << result.error().message()
                << '\n';
    if (const auto request = selection_request_of(bytes))
      streams.err << "note: " << kRequestNote << request->dump() << '\n';
    return finish(streams, kExitFailure);
  }
  wire::StateValues values;
  values.assign(result.frame());
  streams.out << wire::to_canonical_json(values) << '\n';
  return finish(streams, kExitOk);
}

int decode_hex_lines(Streams streams) {
  wire::StateValues values;
  std::string json;
  for_each_nonblank_line(streams.in, [&](std::size_t number, std::string_view text) {
    const wire::Parsed<std::vector<std::uint8_t>> bytes = wire::from_hex(text);
    if (!bytes) {
      streams.out << error_line("bad_hex", "line " + std::to_string(number) + ": " + bytes.error()) << '\n';
      return true;
    }
    const wire::DecodeResult result = wire::decode(*bytes);
    if (!result) {
      streams.out << error_line(wire::to_string(result.error().category()), result.error().message(),
                                selection_request_of(*bytes))
                  << '\n';
      return true;
    }
    values.assign(result.frame());
    json.clear();
    wire::append_canonical_json(values, json);
    streams.out << json << '\n';
    return true;
  });
  return finish(streams, kExitOk);
}

int encode_json_lines(Streams streams, FrameFormat format) {
  int status = kExitOk;
  std::array<std::uint8_t, wire::kMaxFrameBytes> frame{};
  for_each_nonblank_line(streams.in, [&](std::size_t number, std::string_view text) {
    const wire::Parsed<wire::StateValues> parsed = wire::parse_canonical_json(text);
    if (!parsed) {
      streams.err << "error: line " << number << ": " << parsed.error() << '\n';
      status = kExitFailure;
      return false;
    }
    const wire::StateValues& values = *parsed;
    const wire::EncodeResult result =
        encode(values.packet_number, values.selection, values.storage(), wire::StateValues::layout(), frame);
    if (!result) {
      streams.err << "error: line " << number
                  << ": cannot encode: " << wire::to_string(result.error.category()) << ": "
                  << result.error.message() << '\n';
      status = kExitFailure;
      return false;
    }
    write_frame(streams.out, std::span(frame).first(result.size), format);
    return true;
  });
  return finish(streams, status);
}

int write_selection_request(Streams streams, std::uint8_t packet_number, const wire::Selection& selection,
                            FrameFormat format) {
  std::array<std::uint8_t, wire::kSelectionRequestBytes> frame{};
  const wire::EncodeResult result = encode_selection_request(packet_number, selection, frame);
  if (!result) {
    streams.err << "error: " << wire::to_string(result.error.category()) << ": " << result.error.message()
                << '\n';
    return finish(streams, kExitFailure);
  }
  write_frame(streams.out, std::span(frame).first(result.size), format);
  return finish(streams, kExitOk);
}

}  // namespace rsg::tools::frame
