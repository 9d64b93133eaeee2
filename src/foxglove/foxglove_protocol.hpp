// The Foxglove WebSocket protocol (https://github.com/foxglove/ws-protocol, spec v1) as rsg_view
// speaks it: what a client may send, parsed into plain structs, and the server's messages built as
// text or as the binary header of a message frame. No I/O here: the server owns the sockets.
//
// Both subprotocol names in use are the same protocol: `foxglove.websocket.v1` (npm's client,
// PlotJuggler, Lichtblick) and `foxglove.sdk.v1` (the current Foxglove app and SDK).
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

namespace rsg::foxglove {

inline constexpr std::string_view kLegacySubprotocol = "foxglove.websocket.v1";
inline constexpr std::string_view kSdkSubprotocol = "foxglove.sdk.v1";

/// The subprotocol to answer for a `Sec-WebSocket-Protocol` request header (a comma-separated
/// list): the first one offered that rsg speaks; empty when none is.
std::string_view choose_subprotocol(std::string_view offered);

struct Subscription {
  std::uint32_t id = 0;
  std::uint32_t channel_id = 0;
};
struct Subscribe {
  std::vector<Subscription> subscriptions;
};
struct Unsubscribe {
  std::vector<std::uint32_t> subscription_ids;
};
/// A well-formed request for a capability rsg_view does not advertise (publishing, services, ...).
struct Unsupported {
  std::string op;
};
/// Anything else: not JSON, not an object, a missing or mistyped field, too many entries.
struct Malformed {
  std::string reason;
};
using ClientMessage = std::variant<Subscribe, Unsubscribe, Unsupported, Malformed>;

/// At most this many subscriptions or ids in one request; more is Malformed.
inline constexpr std::size_t kMaxEntriesPerRequest = 1024;

/// Parses one text frame from a client. Never throws.
ClientMessage parse_client_message(std::string_view text) noexcept;

struct Channel {
  std::uint32_t id = 0;
  std::string topic;
  std::string encoding;         ///< "cdr" or "json"
  std::string schema_name;      ///< e.g. "rsg::RobotState", "foxglove.FrameTransform"
  std::string schema;           ///< the schema text (IDL, .msg or JSON Schema)
  std::string schema_encoding;  ///< "omgidl", "ros2msg" or "jsonschema"
};

std::string server_info(std::string_view name, std::string_view session_id);
std::string advertise(std::span<const Channel> channels);

enum class Level : int { info = 0, warning = 1, error = 2 };
/// `id` lets a client replace an earlier status of the same id (e.g. a running drop counter).
std::string status(Level level, std::string_view message, std::string_view id = {});

/// Opcode 0x01, subscription id (u32 LE), receive time in ns (u64 LE): the payload follows.
inline constexpr std::size_t kMessageHeaderSize = 13;
std::array<std::uint8_t, kMessageHeaderSize> message_header(std::uint32_t subscription_id,
                                                            std::uint64_t time_ns) noexcept;

}  // namespace rsg::foxglove
