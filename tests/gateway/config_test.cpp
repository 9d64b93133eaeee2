#include "rsg/gateway/config.hpp"

#include <gtest/gtest.h>

#include <set>

namespace rsg::gateway {
namespace {

GatewayConfig parse_ok(std::string_view yaml) {
  const ConfigResult result = parse_gateway_config(yaml);
  EXPECT_TRUE(result) << "line " << result.error().line << ": " << result.error().message;
  return result ? result.config() : GatewayConfig{};
}

ConfigError parse_error(std::string_view yaml) {
  const ConfigResult result = parse_gateway_config(yaml);
  EXPECT_FALSE(result) << yaml;
  return result ? ConfigError{} : result.error();
}

TEST(GatewayConfig, KeysAreUniqueAndSpelledLikeFlags) {
  std::set<std::string_view> names;
  for (const ConfigKey& key : config_keys()) {
    EXPECT_TRUE(names.insert(key.name).second) << key.name;
    EXPECT_EQ(key.name.find('_'), std::string_view::npos) << key.name;
    EXPECT_FALSE(key.help.empty()) << key.name;
  }
}

TEST(GatewayConfig, EmptyDocumentKeepsTheDefaults) {
  const GatewayConfig config = parse_ok("");
  EXPECT_EQ(config.topic, "robot_state");
  EXPECT_EQ(config.domain, 0);
  EXPECT_EQ(config.expected_rate, 1000.0);
  EXPECT_EQ(config.status_topic, "rsg_gateway_status");
}

TEST(GatewayConfig, ReadsEveryKind) {
  const GatewayConfig config = parse_ok(R"(
listen: 0.0.0.0:5000
domain: 7
expected-rate: 500.5
allow-from: [10.0.0.0/8, "::1"]
send-to: 127.0.0.1:6000,127.0.0.1:6001
egress-topic: commands
request-groups: [2, 5]
)");
  EXPECT_EQ(config.listen, "0.0.0.0:5000");
  EXPECT_EQ(config.domain, 7);
  EXPECT_EQ(config.expected_rate, 500.5);
  EXPECT_EQ(config.allow_from, (std::vector<std::string>{"10.0.0.0/8", "::1"}));
  EXPECT_EQ(config.send_to, (std::vector<std::string>{"127.0.0.1:6000", "127.0.0.1:6001"}));
  EXPECT_EQ(config.request_groups, (std::vector<std::string>{"2", "5"}));
  EXPECT_FALSE(check_config(config).has_value()) << *check_config(config);
}

TEST(GatewayConfig, StartsFromTheGivenDefaults) {
  GatewayConfig defaults;
  defaults.topic = "arm1";
  EXPECT_EQ(parse_gateway_config("domain: 3", defaults).config().topic, "arm1");
}

TEST(GatewayConfig, UnknownKeyNamesItsLine) {
  const ConfigError error = parse_error("listen: 0.0.0.0:5000\n\nlissten: x\n");
  EXPECT_EQ(error.line, 3);
  EXPECT_NE(error.message.find("lissten"), std::string::npos);
}

TEST(GatewayConfig, WrongTypesNameKeyAndLine) {
  EXPECT_EQ(parse_error("topic: t\ndomain: seven\n").line, 2);
  EXPECT_NE(parse_error("domain: 3.5").message.find("domain"), std::string::npos);
  EXPECT_EQ(parse_error("expected-rate: fast").line, 1);
  EXPECT_EQ(parse_error("listen: [a, b]").line, 1);
  EXPECT_EQ(parse_error("send-to: {a: b}").line, 1);
  EXPECT_EQ(parse_error("listen:").line, 1);
}

TEST(GatewayConfig, BadValuesNameKeyAndLine) {
  EXPECT_EQ(parse_error("\ndomain: 300").line, 2);
  EXPECT_EQ(parse_error("listen: nohostport").line, 1);
  EXPECT_EQ(parse_error("send-to: [127.0.0.1:0]").line, 1);
  EXPECT_EQ(parse_error("allow-from: 10.0.0.0/40").line, 1);
  EXPECT_EQ(parse_error("request-groups: 6").line, 1);
  EXPECT_EQ(parse_error("request-fields: q,qq").line, 1);
  EXPECT_EQ(parse_error("expected-rate: 0").line, 1);
  EXPECT_EQ(parse_error("log-level: loud").line, 1);
}

TEST(GatewayConfig, DuplicateKeyIsAnError) {
  const ConfigError error = parse_error("domain: 1\ndomain: 2\n");
  EXPECT_EQ(error.line, 2);
}

TEST(GatewayConfig, SyntaxErrorNamesItsLine) {
  const ConfigError error = parse_error("listen: 0.0.0.0:5000\ntopic: [unclosed\n");
  EXPECT_GE(error.line, 2);
  EXPECT_FALSE(error.message.empty());
}

TEST(GatewayConfig, TopLevelMustBeAMapping) {
  EXPECT_FALSE(parse_error("- listen\n- topic\n").message.empty());
  EXPECT_FALSE(parse_error("just text").message.empty());
}

TEST(GatewayConfig, CombinationsAreChecked) {
  GatewayConfig config;
  EXPECT_TRUE(check_config(config).has_value());  // nothing to do

  config.listen = "0.0.0.0:5000";
  EXPECT_FALSE(check_config(config).has_value());

  config.send_to = {"127.0.0.1:6000"};
  EXPECT_NE(check_config(config)->find("--egress-topic"), std::string::npos);
  config.egress_topic = "out";
  EXPECT_FALSE(check_config(config).has_value());

  config.robot = "127.0.0.1:7000";
  EXPECT_NE(check_config(config)->find("--request-groups"), std::string::npos);
  config.request_fields = {"q", "time"};
  EXPECT_FALSE(check_config(config).has_value());

  config.listen.clear();
  EXPECT_NE(check_config(config)->find("--listen"), std::string::npos);
}

TEST(GatewayConfig, ChecksValuesGivenAsFlagsToo) {
  GatewayConfig config;
  config.listen = "0.0.0.0:5000";
  config.domain = -1;
  EXPECT_NE(check_config(config)->find("--domain"), std::string::npos);
}

TEST(GatewayConfig, RequestedSelectionIsTheUnionOfGroupsAndFields) {
  GatewayConfig config;
  config.request_groups = {"2"};
  config.request_fields = {"time"};
  Selection expected;
  expected.add_group(2);
  expected.add(Field::time);
  EXPECT_EQ(requested_selection(config), expected);
}

TEST(GatewayConfig, HostileInputIsAnErrorNotACrash) {
  EXPECT_FALSE(parse_gateway_config(std::string(10000, '[')));
  EXPECT_FALSE(parse_gateway_config("&a [*a]"));
  EXPECT_FALSE(parse_gateway_config(std::string_view("listen: \0x", 10)));
}

}  // namespace
}  // namespace rsg::gateway
