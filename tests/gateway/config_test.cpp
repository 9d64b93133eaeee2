#include "gateway/config.hpp"

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

TEST(GatewayConfig, ReadsDiscoveryServersAndPeers) {
  const GatewayConfig config = parse_ok(R"(
discovery-server: [198.18.0.2:11811, "1@gw2.plant:11811"]
peer: 198.18.0.3,198.18.0.4:7410
)");
  EXPECT_EQ(config.discovery_servers, (std::vector<std::string>{"198.18.0.2:11811", "1@gw2.plant:11811"}));
  EXPECT_EQ(config.peers, (std::vector<std::string>{"198.18.0.3", "198.18.0.4:7410"}));
  EXPECT_NE(parse_error("discovery-server: 198.18.0.2").message.find("HOST:PORT"), std::string::npos);
  EXPECT_NE(parse_error("discovery-server: 300@198.18.0.2:11811").message.find("0..255"), std::string::npos);
  EXPECT_NE(parse_error("peer: 198.18.0.3:0").message.find("port"), std::string::npos);
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

TEST(GatewayConfig, UnknownKeySuggestsTheNearest) {
  const ConfigError underscore = parse_error("listen: 0.0.0.0:5000\nstats_file: /run/rsg/stats.json\n");
  EXPECT_EQ(underscore.line, 2);
  EXPECT_EQ(underscore.message, "unknown key 'stats_file': did you mean 'stats-file'?");
  EXPECT_NE(parse_error("lissten: x").message.find("did you mean 'listen'?"), std::string::npos);
  EXPECT_NE(parse_error("Expected_Rate: 5").message.find("did you mean 'expected-rate'?"), std::string::npos);
  // Nothing near: the list of every key instead of a guess.
  const ConfigError far = parse_error("colour: blue");
  EXPECT_EQ(far.message.find("did you mean"), std::string::npos);
  EXPECT_NE(far.message.find("known: listen, allow-from"), std::string::npos);
  EXPECT_EQ(nearest_key("xyz"), std::nullopt);
}

TEST(GatewayConfig, MissingColonNamesTheLineItIsMissingFrom) {
  // yaml-cpp itself reports line 4 ("illegal map value"): the key of line 3 runs on into it.
  const ConfigError error =
      parse_error("listen: 127.0.0.1:5000\ndomain: 3\ntopic robot\nexpected-rate: 1000\n");
  EXPECT_EQ(error.line, 3);
  EXPECT_NE(error.message.find("missing ':'"), std::string::npos) << error.message;
  // Comments, list items and indented continuations are not such lines.
  EXPECT_EQ(
      parse_error("# gateway\nallow-from:\n- 10.0.0.1\nsend-to: [a:1,\n  b:2]\ntopic x\ndomain: 1\n").line,
      6);
}

TEST(GatewayConfig, AColonlessLastLineGetsTheSameHintNotTheListOfKeys) {
  // yaml-cpp reads "topic robot" on the last line as a key without a value.
  for (const char* text : {"listen: 127.0.0.1:5000\ndomain: 3\ntopic robot\n", "listen 127.0.0.1:5000\n"}) {
    const ConfigError error = parse_error(text);
    EXPECT_NE(error.message.find("not a 'key: value' line (a missing ':' after '"), std::string::npos)
        << error.message;
    EXPECT_EQ(error.message.find("known:"), std::string::npos) << error.message;
  }
  // A word that is no key is still an unknown key.
  EXPECT_NE(parse_error("listen: a:1\nfoo bar\n").message.find("unknown key 'foo bar'"), std::string::npos);
}

TEST(GatewayConfig, AnInstanceNamesItsPartitionAndTheUnitsDirectories) {
  const auto defaults = instance_defaults("robot2");
  ASSERT_TRUE(std::holds_alternative<GatewayConfig>(defaults));
  const GatewayConfig& config = std::get<GatewayConfig>(defaults);
  EXPECT_EQ(config.partition, "robot2");
  EXPECT_EQ(config.stats_file, "/run/rsg/robot2/stats.json");
  EXPECT_EQ(config.pcap_dir, "/var/lib/rsg/robot2");
  // Under the file: what the file sets wins.
  const ConfigResult parsed = parse_gateway_config("partition: robot1\n", config);
  ASSERT_TRUE(parsed);
  EXPECT_EQ(parsed.config().partition, "robot1");
  EXPECT_EQ(parsed.config().stats_file, "/run/rsg/robot2/stats.json");
  // A ROS 2 instance: ROS 2 uses no partitions, so the instance's gives way (the unit's ros2 file).
  const ConfigResult ros2 = parse_gateway_config("ros2: true\n", config);
  ASSERT_TRUE(ros2) << ros2.error().message;
  EXPECT_EQ(ros2.config().partition, "");
  EXPECT_FALSE(parse_gateway_config("ros2: true\npartition: robot1\n", config));
  for (const char* bad : {"", ".", "..", "a/b"})
    EXPECT_TRUE(std::holds_alternative<std::string>(instance_defaults(bad)));
}

TEST(GatewayConfig, TheUnitsDirectoriesAreOneNameBelowTheirRoots) {
  EXPECT_EQ(unit_directory_kind("/run/rsg/robot1").value_or(""), "RuntimeDirectory=");
  EXPECT_EQ(unit_directory_kind("/run/rsg/robot1/").value_or(""), "RuntimeDirectory=");
  EXPECT_EQ(unit_directory_kind("/var/lib/rsg/robot1").value_or(""), "StateDirectory=");
  for (const char* other : {"/run/rsg", "/run/rsg/", "/run/rsg/a/b", "/run/rsg/..", "/run/rsgx/a", "/tmp/a"})
    EXPECT_FALSE(unit_directory_kind(other).has_value()) << other;
}

TEST(GatewayConfig, LogLevelInAnyCase) {
  const GatewayConfig config = parse_ok("log-level: WARN");
  EXPECT_EQ(log_level_name(config), "warn");
  EXPECT_NE(parse_error("log-level: verbose").message.find("'verbose' is not one of"), std::string::npos);
}

TEST(GatewayConfig, NamesWithoutControlCharacters) {
  EXPECT_EQ(parse_error("domain: 1\npartition: \"a\\nb\"\n").line, 2);
  EXPECT_NE(parse_error("name: \"x\\ty\"").message.find("control characters"), std::string::npos);
  EXPECT_NE(parse_error("topic: \"\"").message.find("must not be empty"), std::string::npos);
}

TEST(GatewayConfig, ProfilesAreAListLikeTheTools) {
  EXPECT_EQ(parse_ok("profiles: [a.xml, dir]").profiles, (std::vector<std::string>{"a.xml", "dir"}));
  EXPECT_EQ(parse_ok("profiles: a.xml,dir").profiles, (std::vector<std::string>{"a.xml", "dir"}));
  EXPECT_EQ(parse_ok("profiles: a.xml").profiles, (std::vector<std::string>{"a.xml"}));
  EXPECT_NE(parse_error("profiles: a.xml,,b").message.find("empty path"), std::string::npos);
}

// What the gateway would allocate, or walk per datagram, at start-up is bounded when it is read:
// these were accepted and then failed with std::bad_alloc (or took gigabytes) at start-up.
TEST(GatewayConfig, ValuesThatCannotBeAllocatedAreRefusedByName) {
  GatewayConfig config;
  config.listen = "127.0.0.1:17000";
  config.pcap_dir = "/tmp";
  config.pcap_ring = 600;
  config.expected_rate = 100000;
  const auto ring = check_config(config);
  ASSERT_TRUE(ring.has_value());
  EXPECT_NE(ring->find("--pcap-ring"), std::string::npos) << *ring;
  EXPECT_NE(ring->find("--expected-rate 100000"), std::string::npos) << *ring;
  config.pcap_ring = 120;  // 120 s at 1 kHz: the largest ring allowed
  config.expected_rate = 1000;
  EXPECT_FALSE(check_config(config).has_value()) << *check_config(config);

  GatewayConfig rates;
  rates.listen = "127.0.0.1:17000";
  for (int i = 0; i < 2000; ++i) rates.rate_topics.push_back("rate" + std::to_string(i) + ":10");
  EXPECT_NE(check_config(rates).value_or("").find("--rate-topic: 2000 entries, at most 32"),
            std::string::npos);
  rates.rate_topics = {"a:10", "a:every:2"};
  EXPECT_NE(check_config(rates).value_or("").find("'a' is given twice"), std::string::npos);

  GatewayConfig sources;
  sources.listen = "127.0.0.1:17000";
  sources.allow_from.assign(200000, "10.0.0.1");
  EXPECT_NE(check_config(sources).value_or("").find("--allow-from: 200000 entries, at most 256"),
            std::string::npos);
  sources.allow_from.assign(kMaxAllowFrom, "10.0.0.1");
  EXPECT_FALSE(check_config(sources).has_value());

  GatewayConfig egress;
  egress.egress_topic = "cmd";
  egress.send_to.assign(kMaxSendTo + 1, "127.0.0.1:9");
  EXPECT_NE(check_config(egress).value_or("").find("--send-to: 65 entries"), std::string::npos);
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

TEST(GatewayConfig, Ros2ModeAndNamespace) {
  const GatewayConfig config = parse_ok("listen: 0.0.0.0:5000\nros2: true\nros2-namespace: /robot1\n");
  EXPECT_TRUE(config.ros2);
  EXPECT_EQ(config.ros2_namespace, "/robot1");
  EXPECT_FALSE(check_config(config).has_value());

  EXPECT_EQ(parse_error("ros2: yes\n").message, "ros2: expected true or false");
  EXPECT_NE(parse_error("ros2: true\nros2-namespace: /robot 1\n").message.find("ros2-namespace"),
            std::string::npos);
  EXPECT_NE(parse_error("ros2: true\nros2-namespace: /1robot\n").message.find("digit"), std::string::npos);
  EXPECT_NE(parse_error("ros2-namespace: /robot1\n").message.find("needs --ros2"), std::string::npos);

  GatewayConfig partitioned = config;
  partitioned.partition = "p";
  EXPECT_NE(check_config(partitioned)->find("partitions"), std::string::npos);

  // In ROS 2 mode egress has a default topic (robot_state_cmd): --send-to alone turns it on.
  GatewayConfig egress = config;
  egress.send_to = {"127.0.0.1:6000"};
  EXPECT_TRUE(egress.has_egress());
  EXPECT_FALSE(check_config(egress).has_value());
}

TEST(GatewayConfig, RateTopicsAreNameColonHzOrEveryN) {
  const GatewayConfig config = parse_ok("rate-topic: [slow:50, ui:2.5, tenth:every:10, ns:a:every:3]\n");
  ASSERT_EQ(config.rate_topics.size(), 4u);
  const auto ui = parse_rate_topic(config.rate_topics[1]);
  ASSERT_TRUE(ui);
  EXPECT_EQ(ui->name, "ui");
  EXPECT_EQ(ui->rate.every, 0u);
  EXPECT_EQ(ui->rate.period, std::chrono::nanoseconds(400'000'000));
  const auto tenth = parse_rate_topic(config.rate_topics[2]);
  ASSERT_TRUE(tenth);
  EXPECT_EQ(tenth->name, "tenth");
  EXPECT_EQ(tenth->rate.every, 10u);
  const auto colons = parse_rate_topic(config.rate_topics[3]);
  ASSERT_TRUE(colons);
  EXPECT_EQ(colons->name, "ns:a");
  EXPECT_EQ(colons->rate.every, 3u);
  for (const char* bad : {"slow", "slow:", ":50", "slow:0", "slow:-1", "slow:50hz", "slow:20000",
                          "slow:every:", "slow:every:0", ":every:5", "every:5:"})
    EXPECT_FALSE(parse_rate_topic(bad)) << bad;
  EXPECT_NE(parse_error("rate-topic: slow\n").message.find("NAME:HZ"), std::string::npos);
}

TEST(GatewayConfig, Ros2StandardTopicsTakeARateNamesAndFrames) {
  const GatewayConfig config = parse_ok(
      "listen: 0.0.0.0:5000\njoint-states: 100\ntf: every:10\nexternal-wrench: 2.5\n"
      "joint-names: [a1, a2, a3, a4, a5, a6, a7]\nbase-frame: world\nee-frame: tool0\nwrench-frame: tool0\n");
  EXPECT_FALSE(check_config(config).has_value());
  EXPECT_EQ(config.joint_names.back(), "a7");
  EXPECT_EQ(config.base_frame, "world");
  const auto hz = parse_decimation(config.joint_states);
  ASSERT_TRUE(hz);
  EXPECT_EQ(hz->every, 0u);
  EXPECT_EQ(hz->period, std::chrono::milliseconds(10));
  const auto every = parse_decimation(config.tf);
  ASSERT_TRUE(every);
  EXPECT_EQ(every->every, 10u);
  EXPECT_EQ(GatewayConfig().joint_names.front(), "panda_joint1");
  EXPECT_EQ(GatewayConfig().wrench_frame, "panda_link0");
  for (const char* bad :
       {"0", "-5", "100hz", "20000", "every:", "every:0", "every:x", "every:2000000", "every"})
    EXPECT_FALSE(parse_decimation(bad)) << bad;
  EXPECT_NE(parse_error("tf: every:0\n").message.find("every:N"), std::string::npos);
  EXPECT_NE(parse_error("joint-names: [a, b]\n").message.find("7 names"), std::string::npos);
  EXPECT_NE(parse_error("base-frame: /world\n").message.find("'/'"), std::string::npos);
  GatewayConfig egress_only;
  egress_only.egress_topic = "cmd";
  egress_only.send_to = {"127.0.0.1:5001"};
  egress_only.joint_states = "100";
  EXPECT_NE(check_config(egress_only).value_or("").find("need --listen"), std::string::npos);
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
  wire::Selection expected;
  expected.add_group(2);
  expected.add(wire::Field::time);
  EXPECT_EQ(requested_selection(config), expected);
}

TEST(GatewayConfig, HostileInputIsAnErrorNotACrash) {
  EXPECT_FALSE(parse_gateway_config(std::string(10000, '[')));
  EXPECT_FALSE(parse_gateway_config("&a [*a]"));
  EXPECT_FALSE(parse_gateway_config(std::string_view("listen: \0x", 10)));
}

TEST(GatewayConfig, FlightRecorderNeedsADirectoryAndAListeningSocket) {
  const GatewayConfig config = parse_ok("listen: 127.0.0.1:17000\npcap-ring: 2.5\npcap-dir: /tmp\n");
  EXPECT_EQ(config.pcap_ring, 2.5);
  EXPECT_EQ(config.pcap_dir, "/tmp");
  EXPECT_FALSE(check_config(config).has_value());

  GatewayConfig broken = config;
  broken.pcap_dir.clear();
  EXPECT_NE(check_config(broken)->find("--pcap-ring needs --pcap-dir"), std::string::npos);
  broken = config;
  broken.pcap_ring = -1;
  EXPECT_NE(check_config(broken)->find("--pcap-ring: must be in 0..600"), std::string::npos);
  broken = config;
  broken.listen.clear();
  broken.egress_topic = "out";
  broken.send_to = {"127.0.0.1:18000"};
  EXPECT_NE(check_config(broken)->find("--pcap-ring needs --listen"), std::string::npos);
}

// Issue 51: a check that reads another key saw only the lines above it, so the same keys were
// refused in one order and accepted in the other. Checks run once the whole file is read.
TEST(GatewayConfig, ACrossKeyCheckDoesNotDependOnTheOrderOfTheLines) {
  for (const std::string_view yaml :
       {"pcap-ring: 600\nexpected-rate: 200\n", "expected-rate: 200\npcap-ring: 600\n"}) {
    const GatewayConfig config = parse_ok(yaml);
    EXPECT_EQ(config.pcap_ring, 600) << yaml;
    EXPECT_EQ(config.expected_rate, 200) << yaml;
  }
  // Too large in both orders, named on the line of the key whose check fails.
  for (const auto& [yaml, line] :
       {std::pair<std::string_view, int>{"pcap-ring: 600\nexpected-rate: 201\n", 1},
        {"expected-rate: 201\npcap-ring: 600\n", 2}}) {
    const ConfigError error = parse_error(yaml);
    EXPECT_EQ(error.line, line) << yaml;
    EXPECT_NE(error.message.find("pcap-ring: 600 s at --expected-rate 201"), std::string::npos)
        << error.message;
  }
}

TEST(GatewayConfig, FlightRecorderIsBoundedByDefaultAndItsBoundsAreChecked) {
  const GatewayConfig defaults;
  EXPECT_EQ(defaults.pcap_min_interval, 10);
  EXPECT_EQ(defaults.pcap_max_files, 100);
  EXPECT_EQ(defaults.pcap_max_mb, 500);
  EXPECT_FALSE(defaults.pcap_all_sources);
  const GatewayConfig config =
      parse_ok("pcap-min-interval: 0\npcap-max-files: 3\npcap-max-mb: 1\npcap-all-sources: true\n");
  EXPECT_EQ(config.pcap_min_interval, 0);
  EXPECT_EQ(config.pcap_max_files, 3);
  EXPECT_EQ(config.pcap_max_mb, 1);
  EXPECT_TRUE(config.pcap_all_sources);
  EXPECT_FALSE(parse_gateway_config("pcap-min-interval: -1\n"));
  EXPECT_FALSE(parse_gateway_config("pcap-max-files: 0\n"));
  EXPECT_FALSE(parse_gateway_config("pcap-max-mb: 0\n"));
}

}  // namespace
}  // namespace rsg::gateway
