// The Foxglove protocol messages on their own: what clients send is parsed or refused, never thrown.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "foxglove/foxglove_protocol.hpp"

namespace rsg::foxglove {
namespace {

TEST(FoxgloveProtocol, AnswersTheSubprotocolOffered) {
  EXPECT_EQ(choose_subprotocol("foxglove.websocket.v1"), kLegacySubprotocol);
  EXPECT_EQ(choose_subprotocol("foxglove.sdk.v1"), kSdkSubprotocol);
  EXPECT_EQ(choose_subprotocol("chat, foxglove.sdk.v1 ,foxglove.websocket.v1"), kSdkSubprotocol);
  EXPECT_EQ(choose_subprotocol("chat"), "");
  EXPECT_EQ(choose_subprotocol(""), "");
}

TEST(FoxgloveProtocol, ParsesSubscribeAndUnsubscribe) {
  const auto subscribe = parse_client_message(
      R"({"op":"subscribe","subscriptions":[{"id":7,"channelId":1},{"id":8,"channelId":4294967295}]})");
  ASSERT_TRUE(std::holds_alternative<Subscribe>(subscribe));
  const auto& list = std::get<Subscribe>(subscribe).subscriptions;
  ASSERT_EQ(list.size(), 2U);
  EXPECT_EQ(list[0].id, 7U);
  EXPECT_EQ(list[0].channel_id, 1U);
  EXPECT_EQ(list[1].channel_id, 4294967295U);

  const auto unsubscribe = parse_client_message(R"({"op":"unsubscribe","subscriptionIds":[7,8]})");
  ASSERT_TRUE(std::holds_alternative<Unsubscribe>(unsubscribe));
  EXPECT_EQ(std::get<Unsubscribe>(unsubscribe).subscription_ids, (std::vector<std::uint32_t>{7, 8}));
}

TEST(FoxgloveProtocol, RefusesMalformedMessages) {
  for (const char* text : {"", "{", "[]", "42", R"({"op":1})", R"({"subscriptions":[]})",
                           R"({"op":"subscribe"})", R"({"op":"subscribe","subscriptions":{}})",
                           R"({"op":"subscribe","subscriptions":[{"id":-1,"channelId":1}]})",
                           R"({"op":"subscribe","subscriptions":[{"id":1.5,"channelId":1}]})",
                           R"({"op":"subscribe","subscriptions":[{"id":4294967296,"channelId":1}]})",
                           R"({"op":"subscribe","subscriptions":[{"id":1}]})",
                           R"({"op":"unsubscribe","subscriptionIds":["1"]})", "\xff\xfe"}) {
    const auto message = parse_client_message(text);
    ASSERT_TRUE(std::holds_alternative<Malformed>(message)) << text;
    EXPECT_FALSE(std::get<Malformed>(message).reason.empty());
  }
  nlohmann::json many{{"op", "unsubscribe"},
                      {"subscriptionIds", std::vector<int>(kMaxEntriesPerRequest + 1, 1)}};
  EXPECT_TRUE(std::holds_alternative<Malformed>(parse_client_message(many.dump())));
}

TEST(FoxgloveProtocol, NamesUnsupportedOperations) {
  const auto message = parse_client_message(R"({"op":"advertise","channels":[]})");
  ASSERT_TRUE(std::holds_alternative<Unsupported>(message));
  EXPECT_EQ(std::get<Unsupported>(message).op, "advertise");
}

TEST(FoxgloveProtocol, BuildsServerMessages) {
  const std::vector<Channel> channels{
      {3, "robot_state", "cdr", "rsg::RobotState", "module rsg {};", "omgidl"}};
  const auto advertised = nlohmann::json::parse(advertise(channels));
  EXPECT_EQ(advertised["op"], "advertise");
  EXPECT_EQ(advertised["channels"][0]["id"], 3);
  EXPECT_EQ(advertised["channels"][0]["schemaEncoding"], "omgidl");
  const auto info = nlohmann::json::parse(server_info("rsg_view", "1"));
  EXPECT_EQ(info["op"], "serverInfo");
  EXPECT_TRUE(info["capabilities"].is_array());
  // Text from a client (invalid UTF-8 here) must not make building a status throw.
  const auto s = nlohmann::json::parse(status(Level::error, "bad \xff op", "x"));
  EXPECT_EQ(s["level"], 2);
  EXPECT_EQ(s["id"], "x");
}

TEST(FoxgloveProtocol, MessageHeaderIsLittleEndian) {
  const auto header = message_header(0x04030201U, 0x0c0b0a0908070605ULL);
  const std::array<std::uint8_t, kMessageHeaderSize> expected{0x01, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12};
  EXPECT_EQ(header, expected);
}

}  // namespace
}  // namespace rsg::foxglove
