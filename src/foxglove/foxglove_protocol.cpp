#include "foxglove/foxglove_protocol.hpp"

#include <limits>
#include <nlohmann/json.hpp>

namespace rsg::foxglove {
namespace {

using nlohmann::json;

// Ids are u32 on the wire; JSON numbers that are negative, fractional or larger are not ids.
bool as_id(const json& value, std::uint32_t& out) {
  if (!value.is_number_unsigned()) return false;
  const auto number = value.get<std::uint64_t>();
  if (number > std::numeric_limits<std::uint32_t>::max()) return false;
  out = static_cast<std::uint32_t>(number);
  return true;
}

ClientMessage parse_subscribe(const json& message) {
  const auto list = message.find("subscriptions");
  if (list == message.end() || !list->is_array()) return Malformed{"subscribe needs a 'subscriptions' array"};
  if (list->size() > kMaxEntriesPerRequest) return Malformed{"too many subscriptions in one request"};
  Subscribe subscribe;
  for (const json& entry : *list) {
    Subscription subscription;
    if (!entry.is_object() || !entry.contains("id") || !entry.contains("channelId") ||
        !as_id(entry["id"], subscription.id) || !as_id(entry["channelId"], subscription.channel_id))
      return Malformed{"each subscription needs an unsigned 32-bit 'id' and 'channelId'"};
    subscribe.subscriptions.push_back(subscription);
  }
  return subscribe;
}

ClientMessage parse_unsubscribe(const json& message) {
  const auto list = message.find("subscriptionIds");
  if (list == message.end() || !list->is_array())
    return Malformed{"unsubscribe needs a 'subscriptionIds' array"};
  if (list->size() > kMaxEntriesPerRequest) return Malformed{"too many subscription ids in one request"};
  Unsubscribe unsubscribe;
  for (const json& entry : *list) {
    std::uint32_t id = 0;
    if (!as_id(entry, id)) return Malformed{"subscription ids are unsigned 32-bit integers"};
    unsubscribe.subscription_ids.push_back(id);
  }
  return unsubscribe;
}

}  // namespace

std::string_view choose_subprotocol(std::string_view offered) {
  while (!offered.empty()) {
    const auto comma = offered.find(',');
    std::string_view name = offered.substr(0, comma);
    offered = comma == std::string_view::npos ? std::string_view{} : offered.substr(comma + 1);
    while (!name.empty() && (name.front() == ' ' || name.front() == '\t')) name.remove_prefix(1);
    while (!name.empty() && (name.back() == ' ' || name.back() == '\t')) name.remove_suffix(1);
    if (name == kLegacySubprotocol) return kLegacySubprotocol;
    if (name == kSdkSubprotocol) return kSdkSubprotocol;
  }
  return {};
}

ClientMessage parse_client_message(std::string_view text) noexcept {
  try {
    // Depth-limited by the size limit of the server's read; no exceptions escape (allow_exceptions off).
    const json message = json::parse(text, nullptr, false);
    if (message.is_discarded()) return Malformed{"not JSON"};
    if (!message.is_object()) return Malformed{"not a JSON object"};
    const auto op = message.find("op");
    if (op == message.end() || !op->is_string()) return Malformed{"no 'op' string"};
    const auto& name = op->get_ref<const std::string&>();
    if (name == "subscribe") return parse_subscribe(message);
    if (name == "unsubscribe") return parse_unsubscribe(message);
    return Unsupported{name};
  } catch (const std::exception& error) {  // std::bad_alloc
    return Malformed{error.what()};
  }
}

std::string server_info(std::string_view name, std::string_view session_id) {
  return json{{"op", "serverInfo"},
              {"name", name},
              {"capabilities", json::array()},
              {"supportedEncodings", json::array()},
              {"metadata", json::object()},
              {"sessionId", session_id}}
      .dump();
}

std::string advertise(std::span<const Channel> channels) {
  json list = json::array();
  for (const Channel& channel : channels)
    list.push_back({{"id", channel.id},
                    {"topic", channel.topic},
                    {"encoding", channel.encoding},
                    {"schemaName", channel.schema_name},
                    {"schema", channel.schema},
                    {"schemaEncoding", channel.schema_encoding}});
  return json{{"op", "advertise"}, {"channels", std::move(list)}}.dump();
}

std::string status(Level level, std::string_view message, std::string_view id) {
  json out{{"op", "status"}, {"level", static_cast<int>(level)}, {"message", message}};
  if (!id.empty()) out["id"] = id;
  // Client text may be echoed in a message: never fail on invalid UTF-8 from outside.
  return out.dump(-1, ' ', false, json::error_handler_t::replace);
}

std::array<std::uint8_t, kMessageHeaderSize> message_header(std::uint32_t subscription_id,
                                                            std::uint64_t time_ns) noexcept {
  std::array<std::uint8_t, kMessageHeaderSize> header{};
  header[0] = 0x01;
  for (int i = 0; i < 4; ++i) header[1 + i] = static_cast<std::uint8_t>(subscription_id >> (8 * i));
  for (int i = 0; i < 8; ++i) header[5 + i] = static_cast<std::uint8_t>(time_ns >> (8 * i));
  return header;
}

}  // namespace rsg::foxglove
