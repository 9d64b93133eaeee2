// parse_client_message() on arbitrary text, as rsg_view gets it from any WebSocket client. It must
// never crash or throw; what it accepts must be within the request limits, and a refusal must say why
// (the reason goes back to the client as an error status, which must build from any text).
#include <cstdint>
#include <string_view>
#include <variant>

#include "foxglove/foxglove_protocol.hpp"
#include "tests/fuzz/fuzz_check.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace rsg::foxglove;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const ClientMessage message = parse_client_message(text);
  if (const auto* subscribe = std::get_if<Subscribe>(&message))
    FUZZ_REQUIRE(subscribe->subscriptions.size() <= kMaxEntriesPerRequest);
  if (const auto* unsubscribe = std::get_if<Unsubscribe>(&message))
    FUZZ_REQUIRE(unsubscribe->subscription_ids.size() <= kMaxEntriesPerRequest);
  if (const auto* unsupported = std::get_if<Unsupported>(&message))
    FUZZ_REQUIRE(!status(Level::error, "unsupported operation '" + unsupported->op + "'").empty());
  if (const auto* malformed = std::get_if<Malformed>(&message)) {
    FUZZ_REQUIRE(!malformed->reason.empty());
    FUZZ_REQUIRE(!status(Level::error, malformed->reason).empty());
  }
  FUZZ_REQUIRE(choose_subprotocol(text).empty() || choose_subprotocol(text) == kSdkSubprotocol ||
               choose_subprotocol(text) == kLegacySubprotocol);
  return 0;
}
