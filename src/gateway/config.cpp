#include "gateway/config.hpp"

#include <fmt/format.h>
#include <sched.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <initializer_list>
#include <set>
#include <string_view>

#include "gateway/source_filter.hpp"
#include "rsg/dds/ros2.hpp"
#include "rsg/transport/host_port.hpp"
#include "rsg/wire/frame.hpp"
#include "wire/internal/number.hpp"

namespace rsg::gateway {
namespace {

std::string join(const std::vector<std::string>& items) {
  std::string joined;
  for (const auto& item : items) joined += (joined.empty() ? "" : ",") + item;
  return joined;
}

// Syntax only (rsg/transport/host_port.hpp): names are resolved when the gateway starts.
std::string check_host_port(const std::string& value, transport::HostPortRule rule) {
  return transport::parse_host_port(value, rule).error();
}

std::string check_optional_host_port(const std::string& value) {
  return value.empty() ? std::string() : check_host_port(value, transport::HostPortRule::kPortRequired);
}

std::string check_range(int value, int low, int high) {
  return value >= low && value <= high
             ? ""
             : std::to_string(value) + " is not in " + std::to_string(low) + ".." + std::to_string(high);
}

std::string check_not_empty(const std::string& value) { return value.empty() ? "must not be empty" : ""; }

/// Empty when `value` is one of `allowed`, else what is wrong with it.
std::string check_one_of(const std::string& value, std::initializer_list<std::string_view> allowed) {
  if (std::ranges::find(allowed, value) != allowed.end()) return {};
  std::string list;
  for (const std::string_view name : allowed) list += (list.empty() ? "" : ", ") + std::string(name);
  return "'" + value + "' is not one of " + list;
}

// A topic, partition or gateway name: no control character, which would split the log lines, the
// status and the metrics that show it.
std::string check_name(const std::string& value, bool may_be_empty) {
  if (!may_be_empty && value.empty()) return "must not be empty";
  if (std::ranges::any_of(value, [](unsigned char c) { return c < 0x20 || c == 0x7f; }))
    return "must not contain control characters";
  return {};
}

// The first complaint of `parse` (a parser returning wire::Parsed) about one of `values`, or "".
template <class Parse>
std::string check_each(const std::vector<std::string>& values, Parse parse) {
  for (const auto& value : values)
    if (auto parsed = parse(value); !parsed) return parsed.error();
  return {};
}

std::string check_decimation(const std::string& value) {
  return value.empty() || parse_decimation(value)
             ? std::string()
             : "'" + value + "' is not HZ (in (0, 10000]) or every:N (N in 1..1000000)";
}

// At most `limit` items, and none twice.
std::string check_list_size(const std::vector<std::string>& values, std::size_t limit) {
  if (values.size() > limit)
    return std::to_string(values.size()) + " entries, at most " + std::to_string(limit) + " are allowed";
  return {};
}

std::string lowercase(std::string text) {
  std::ranges::transform(text, text.begin(),
                         [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return text;
}

std::string check_frame(const std::string& value) {
  return value.empty()            ? "must not be empty"
         : value.starts_with('/') ? "TF frame ids do not start with '/'"
                                  : "";
}

constexpr std::array<std::string_view, 6> kLogLevels = {"trace", "debug", "info", "warn", "error", "off"};

const std::array kKeys = {
    ConfigKey{"listen", "Receive raw frames on HOST:PORT (UDP) and publish them", &GatewayConfig::listen,
              [](const GatewayConfig& c) {
                return c.listen.empty() ? ""
                                        : check_host_port(c.listen, transport::HostPortRule::kPortMayBeZero);
              }},
    ConfigKey{"allow-from", "Accept frames only from ADDR[/PREFIX] (repeatable; IPv4 or IPv6)",
              &GatewayConfig::allow_from,
              [](const GatewayConfig& c) {
                if (auto error = check_list_size(c.allow_from, kMaxAllowFrom); !error.empty()) return error;
                for (const auto& network : c.allow_from)
                  if (const auto parsed = parse_network(network); !parsed) return parsed.error();
                return std::string();
              }},
    ConfigKey{"topic", "Topic the received frames are published on", &GatewayConfig::topic,
              [](const GatewayConfig& c) { return check_name(c.topic, false); }},
    ConfigKey{"domain", "DDS domain id", &GatewayConfig::domain,
              [](const GatewayConfig& c) {
                return c.domain >= 0 && c.domain <= 232 ? "" : std::to_string(c.domain) + " is not in 0..232";
              }},
    ConfigKey{"partition", "DDS partition of every topic (default: none)", &GatewayConfig::partition,
              [](const GatewayConfig& c) { return check_name(c.partition, true); }},
    ConfigKey{
        "receive-buffer", "Kernel UDP receive buffer, bytes", &GatewayConfig::receive_buffer,
        [](const GatewayConfig& c) { return c.receive_buffer >= 0 ? "" : std::string("must be >= 0"); }},
    ConfigKey{
        "rate-topic",
        "Also publish the state on NAME at RATE, given as NAME:RATE with RATE as for --joint-states: HZ (at "
        "most HZ times a second, paced by the robot's time when frames carry it, else by arrival) or every:N "
        "(every Nth frame), e.g. robot_state_50hz:50 or robot_state_tenth:every:10 (repeatable)",
        &GatewayConfig::rate_topics,
        [](const GatewayConfig& c) {
          if (auto error = check_list_size(c.rate_topics, kMaxRateTopics); !error.empty()) return error;
          std::set<std::string, std::less<>> names;
          for (const auto& value : c.rate_topics) {
            const auto rate = parse_rate_topic(value);
            if (!rate)
              return "'" + value +
                     "' is not NAME:HZ with HZ in (0, 10000] nor NAME:every:N with N in 1..1000000";
            if (!names.insert(rate->name).second) return "'" + rate->name + "' is given twice";
          }
          return std::string();
        }},
    ConfigKey{"egress-topic", "Send the samples of this topic as raw frames to --send-to",
              &GatewayConfig::egress_topic,
              [](const GatewayConfig& c) { return check_name(c.egress_topic, true); }},
    ConfigKey{"send-to", "Destination HOST:PORT of egress frames (repeatable)", &GatewayConfig::send_to,
              [](const GatewayConfig& c) {
                if (auto error = check_list_size(c.send_to, kMaxSendTo); !error.empty()) return error;
                for (const auto& destination : c.send_to)
                  if (auto error = check_host_port(destination, transport::HostPortRule::kPortRequired);
                      !error.empty())
                    return error;
                return std::string();
              }},
    ConfigKey{"egress-rate", "Egress samples sent to the robot per second at most, Hz (0: --expected-rate)",
              &GatewayConfig::egress_rate,
              [](const GatewayConfig& c) {
                return c.egress_rate == 0 || (c.egress_rate >= 0.1 && c.egress_rate <= 100000)
                           ? std::string()
                           : "must be 0 or in 0.1..100000";
              }},
    ConfigKey{
        "robot", "HOST:PORT the selection request goes to (default: wherever frames come from, once they do)",
        &GatewayConfig::robot, [](const GatewayConfig& c) { return check_optional_host_port(c.robot); }},
    ConfigKey{"request-groups", "Ask the robot for these groups, e.g. 2,5", &GatewayConfig::request_groups,
              [](const GatewayConfig& c) {
                return c.request_groups.empty() ? std::string()
                                                : wire::parse_group_list(join(c.request_groups)).error();
              }},
    ConfigKey{"request-fields", "Ask the robot for these fields, e.g. q,dq,time",
              &GatewayConfig::request_fields,
              [](const GatewayConfig& c) {
                return c.request_fields.empty() ? std::string()
                                                : wire::parse_field_list(join(c.request_fields)).error();
              }},
    ConfigKey{"status-topic", "Topic of the GatewayStatus samples", &GatewayConfig::status_topic,
              [](const GatewayConfig& c) { return check_name(c.status_topic, false); }},
    ConfigKey{"expected-rate",
              "Nominal frame rate, Hz (the link is down after 10 silent periods, at least 10 ms)",
              &GatewayConfig::expected_rate,
              [](const GatewayConfig& c) {
                return c.expected_rate >= 0.1 && c.expected_rate <= 100000 ? std::string()
                                                                           : "must be in 0.1..100000";
              }},
    ConfigKey{"restart-threshold-ms", "A robot `time` going back by more than this is a restart",
              &GatewayConfig::restart_threshold_ms,
              [](const GatewayConfig& c) {
                return c.restart_threshold_ms >= 1 ? "" : std::string("must be >= 1");
              }},
    ConfigKey{"stats-file", "Keep the counters as JSON in this file (rewritten every second and at exit)",
              &GatewayConfig::stats_file, [](const GatewayConfig&) { return std::string(); }},
    ConfigKey{"metrics",
              "Serve Prometheus metrics on http://HOST:PORT/metrics, liveness on /livez (200 while the "
              "gateway runs) and readiness on /readyz (200 while valid frames arrive in time, else 503; "
              "also /healthz)",
              &GatewayConfig::metrics,
              [](const GatewayConfig& c) {
                return c.metrics.empty()
                           ? ""
                           : check_host_port(c.metrics, transport::HostPortRule::kPortMayBeZero);
              }},
    ConfigKey{"name",
              "This gateway's name: the `gateway` label of its metrics (default: the partition, else the "
              "host's name)",
              &GatewayConfig::name, [](const GatewayConfig& c) { return check_name(c.name, true); }},
    ConfigKey{"metrics-max-connections",
              "Connections --metrics holds open at once; at the limit the oldest one still waiting for its "
              "request makes room (docs/security.md)",
              &GatewayConfig::metrics_max_connections,
              [](const GatewayConfig& c) { return check_range(c.metrics_max_connections, 1, 10000); }},
    ConfigKey{
        "metrics-max-connections-per-client",
        "Connections --metrics holds open per client IP address, as for --metrics-max-connections",
        &GatewayConfig::metrics_max_connections_per_client,
        [](const GatewayConfig& c) { return check_range(c.metrics_max_connections_per_client, 1, 10000); }},
    ConfigKey{"metrics-header-timeout-ms",
              "Time a --metrics client has to send its request's header, from connecting or from the "
              "first byte of a request on a kept-alive connection",
              &GatewayConfig::metrics_header_timeout_ms,
              [](const GatewayConfig& c) { return check_range(c.metrics_header_timeout_ms, 10, 600000); }},
    ConfigKey{"metrics-idle-timeout-ms",
              "Time a kept-alive --metrics connection may wait for its next request",
              &GatewayConfig::metrics_idle_timeout_ms,
              [](const GatewayConfig& c) { return check_range(c.metrics_idle_timeout_ms, 10, 3600000); }},
    ConfigKey{
        "pcap-ring",
        "Flight recorder: keep the last SECONDS of raw datagrams in memory and write them as a pcap "
        "file into --pcap-dir on SIGUSR1 and when the link goes down; 0: off",
        &GatewayConfig::pcap_ring,
        [](const GatewayConfig& c) {
          if (!(c.pcap_ring >= 0 && c.pcap_ring <= 600)) return std::string("must be in 0..600");
          // The ring is allocated up front: refuse here what would be std::bad_alloc at start-up.
          if (c.pcap_ring * c.expected_rate > kMaxFlightRecorderDatagrams)
            return fmt::format(
                "{:g} s at --expected-rate {:g} is {:.0f} datagrams to keep, at most {:.0f} are allowed "
                "(a ring of {:.0f} MB)",
                c.pcap_ring, c.expected_rate, c.pcap_ring * c.expected_rate, kMaxFlightRecorderDatagrams,
                2 * kMaxFlightRecorderDatagrams * static_cast<double>(wire::kMaxFrameBytes) / 1e6);
          return std::string();
        }},
    ConfigKey{"pcap-dir", "Directory the flight recorder's pcap files go to", &GatewayConfig::pcap_dir,
              [](const GatewayConfig&) { return std::string(); }},
    ConfigKey{"pcap-min-interval",
              "Flight recorder: at least SECONDS between two dumps, whether the link went down or SIGUSR1 "
              "asked; a request sooner is not dumped and counted (result=\"throttled\"); 0: no limit",
              &GatewayConfig::pcap_min_interval,
              [](const GatewayConfig& c) {
                return c.pcap_min_interval >= 0 && c.pcap_min_interval <= 86400 ? std::string()
                                                                                : "must be in 0..86400";
              }},
    ConfigKey{"pcap-max-files",
              "Flight recorder: keep at most this many of its files (rsg_flight_*.pcap) in --pcap-dir, "
              "deleting the oldest first",
              &GatewayConfig::pcap_max_files,
              [](const GatewayConfig& c) {
                return c.pcap_max_files >= 1 && c.pcap_max_files <= 100000 ? std::string()
                                                                           : "must be in 1..100000";
              }},
    ConfigKey{"pcap-max-mb",
              "Flight recorder: keep at most this many MiB of its files in --pcap-dir, deleting the oldest "
              "first (a dump larger than that keeps its newest datagrams)",
              &GatewayConfig::pcap_max_mb,
              [](const GatewayConfig& c) {
                return c.pcap_max_mb >= 1 && c.pcap_max_mb <= 1048576 ? std::string()
                                                                      : "must be in 1..1048576";
              }},
    ConfigKey{"pcap-all-sources",
              "Flight recorder: keep datagrams from outside --allow-from in the ring too (default: only "
              "those --allow-from accepts, so that a flood from elsewhere cannot push the robot's out)",
              &GatewayConfig::pcap_all_sources, [](const GatewayConfig&) { return std::string(); }},
    ConfigKey{"log-level", "trace, debug, info, warn, error or off", &GatewayConfig::log_level,
              [](const GatewayConfig& c) {
                const std::string level = lowercase(c.log_level);
                if (std::ranges::find(kLogLevels, level) != kLogLevels.end()) return std::string();
                return "'" + c.log_level + "' is not one of trace, debug, info, warn, error, off";
              }},
    ConfigKey{"reload-widens-access",
              "Let a SIGHUP reload widen access: drop allow-from or open it to everyone, change the "
              "participant profile or --profiles (DDS Security), data-sharing off to auto; without it such "
              "a reload is refused, logged and counted (result=\"refused\")",
              &GatewayConfig::reload_widens_access, [](const GatewayConfig&) { return std::string(); }},
    ConfigKey{"log-format",
              "text (one line per event, timestamped unless the journal is stderr) or json (one JSON object "
              "per line: time, level, logger, message)",
              &GatewayConfig::log_format,
              [](const GatewayConfig& c) {
                return check_one_of(c.log_format, {"text", "json"});
              }},
    ConfigKey{"rt-priority",
              "Run the ingress thread SCHED_FIFO at this priority (1..99) and lock the process's memory "
              "(mlockall); 0: off. Needs CAP_SYS_NICE or an rtprio limit, and CAP_IPC_LOCK or a memlock "
              "limit; without them the gateway warns once and runs normally",
              &GatewayConfig::rt_priority,
              [](const GatewayConfig& c) {
                return c.rt_priority >= 0 && c.rt_priority <= 99 ? std::string() : "must be in 0..99";
              }},
    ConfigKey{"cpu",
              "Pin the ingress thread to this CPU (-1: off). Needs no privilege, only a CPU in the "
              "process's cpuset; else a warning",
              &GatewayConfig::cpu,
              [](const GatewayConfig& c) {
                return c.cpu >= -1 && c.cpu < CPU_SETSIZE
                           ? std::string()
                           : "must be -1 or 0.." + std::to_string(CPU_SETSIZE - 1);
              }},
    ConfigKey{"ros2",
              "ROS 2 naming: publish on rt/<ros2-namespace>/<topic> (robot_state), gateway_status and take "
              "egress from robot_state_cmd, with rsg_msgs type names, so ROS 2 nodes subscribe directly",
              &GatewayConfig::ros2,
              [](const GatewayConfig& c) {
                return c.ros2 && !c.partition.empty()
                           ? std::string(
                                 "ROS 2 does not use partitions: drop --partition, use --ros2-namespace")
                           : std::string();
              }},
    ConfigKey{"ros2-namespace", "ROS 2 namespace of the topics with --ros2, e.g. /robot1 (default: none)",
              &GatewayConfig::ros2_namespace,
              [](const GatewayConfig& c) {
                if (!c.ros2_namespace.empty() && !c.ros2) return std::string("needs --ros2");
                return dds::parse_ros2_namespace(c.ros2_namespace).error();
              }},
    ConfigKey{
        "joint-states",
        "Publish sensor_msgs/JointState (q, dq, tau_J) on joint_states (rt/<ros2-namespace>/joint_states "
        "with --ros2) at RATE: HZ (at most, paced like --rate-topic) or every:N (every Nth frame with q)",
        &GatewayConfig::joint_states,
        [](const GatewayConfig& c) { return check_decimation(c.joint_states); }},
    ConfigKey{"joint-names", "The 7 joint names of joint_states, joint 1 first", &GatewayConfig::joint_names,
              [](const GatewayConfig& c) {
                if (c.joint_names.size() != 7) return std::string("needs exactly 7 names");
                for (const auto& name : c.joint_names)
                  if (name.empty()) return std::string("names must not be empty");
                return std::string();
              }},
    ConfigKey{
        "tf",
        "Publish tf2_msgs/TFMessage --base-frame -> --ee-frame from O_T_EE on tf (rt/tf with --ros2) at "
        "RATE (as --joint-states; frames with O_T_EE)",
        &GatewayConfig::tf, [](const GatewayConfig& c) { return check_decimation(c.tf); }},
    ConfigKey{"base-frame", "TF parent frame: the robot's base O", &GatewayConfig::base_frame,
              [](const GatewayConfig& c) { return check_frame(c.base_frame); }},
    ConfigKey{"ee-frame", "TF child frame: the end effector of O_T_EE", &GatewayConfig::ee_frame,
              [](const GatewayConfig& c) { return check_frame(c.ee_frame); }},
    ConfigKey{"external-wrench",
              "Publish geometry_msgs/WrenchStamped from O_F_ext_hat_K on external_wrench "
              "(rt/<ros2-namespace>/external_wrench with --ros2) at RATE (as --joint-states; frames with it)",
              &GatewayConfig::external_wrench,
              [](const GatewayConfig& c) { return check_decimation(c.external_wrench); }},
    ConfigKey{"wrench-frame", "frame_id of external_wrench (O_F_ext_hat_K is expressed in the base frame O)",
              &GatewayConfig::wrench_frame,
              [](const GatewayConfig& c) { return check_frame(c.wrench_frame); }},
    ConfigKey{"profiles",
              "Fast DDS XML profile file or directory; repeat or separate with commas to load several, in "
              "order (default: rsg's xml_profiles)",
              &GatewayConfig::profiles,
              [](const GatewayConfig& c) {
                for (const auto& path : c.profiles)
                  if (path.empty()) return std::string("an empty path");
                return std::string();
              }},
    ConfigKey{"participant-profile", "XML participant profile", &GatewayConfig::participant_profile,
              [](const GatewayConfig& c) { return check_not_empty(c.participant_profile); }},
    ConfigKey{"writer-profile", "XML data writer profile of the state topic", &GatewayConfig::writer_profile,
              [](const GatewayConfig& c) { return check_not_empty(c.writer_profile); }},
    ConfigKey{"reader-profile", "XML data reader profile of the egress topic", &GatewayConfig::reader_profile,
              [](const GatewayConfig& c) { return check_not_empty(c.reader_profile); }},
    ConfigKey{"status-profile", "XML data writer profile of the status topic", &GatewayConfig::status_profile,
              [](const GatewayConfig& c) { return check_not_empty(c.status_profile); }},
    ConfigKey{
        "data-sharing",
        "auto (as the XML profiles say: rsg's let same-host readers read the samples in shared memory) or "
        "off (no writer or reader of the gateway shares memory with another process: the choice for a host "
        "whose local users are not all trusted, docs/security.md)",
        &GatewayConfig::data_sharing,
        [](const GatewayConfig& c) { return check_one_of(c.data_sharing, {"auto", "off"}); }},
    ConfigKey{"discovery-server", transport::kDiscoveryServerHelp, &GatewayConfig::discovery_servers,
              [](const GatewayConfig& c) {
                return check_each(c.discovery_servers, transport::parse_discovery_server);
              }},
    ConfigKey{"peer", transport::kPeerHelp, &GatewayConfig::peers,
              [](const GatewayConfig& c) { return check_each(c.peers, transport::parse_peer); }},
};

const ConfigKey* find_key(std::string_view name) {
  for (const ConfigKey& key : kKeys)
    if (key.name == name) return &key;
  return nullptr;
}

// Edits (insert, delete, substitute) from `a` to `b`: Levenshtein's distance, on short key names.
std::size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t above = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = above;
    }
  }
  return row[b.size()];
}

// A top-level line of a YAML mapping that is not `key: value` ("topic robot"): yaml-cpp reads it as
// the start of a multi-line key and reports the line after it ("illegal map value"), so a syntax
// error is traced back to such a line when one precedes it. Returns its 1-based number, or 0.
int line_without_colon(std::string_view text, int up_to_line) {
  int found = 0;
  int number = 0;
  std::size_t begin = 0;
  while (begin <= text.size() && number < up_to_line) {
    const std::size_t end = std::min(text.find('\n', begin), text.size());
    std::string_view line = text.substr(begin, end - begin);
    begin = end + 1;
    ++number;
    if (line.ends_with('\r')) line.remove_suffix(1);
    if (const auto hash = line.find(" #"); hash != std::string_view::npos) line = line.substr(0, hash);
    while (!line.empty() && (line.back() == ' ' || line.back() == '\t')) line.remove_suffix(1);
    // Only unindented plain lines: anything else continues a value or is YAML syntax of its own.
    if (line.empty() || line.front() == ' ' || line.front() == '\t' || line.front() == '#' ||
        line.front() == '-' || line.front() == '.' || line.front() == ']' || line.front() == '}' ||
        line.front() == '%')
      continue;
    if (line.find(": ") == std::string_view::npos && !line.ends_with(':')) found = number;
  }
  return found;
}

std::string known_keys() {
  std::string names;
  for (const ConfigKey& key : kKeys) names += (names.empty() ? "" : ", ") + std::string(key.name);
  return names;
}

template <class Number>
std::string read_number(const YAML::Node& node, Number& out) {
  const std::string& text = node.Scalar();
  const std::optional<Number> number = wire::internal::parse_number<Number>(text);
  if (!number) return "'" + text + "' is not " + (std::is_integral_v<Number> ? "an integer" : "a number");
  out = *number;
  return {};
}

void split_into(const std::string& list, std::vector<std::string>& out) {
  std::size_t begin = 0;
  while (begin <= list.size()) {
    const std::size_t comma = std::min(list.find(',', begin), list.size());
    out.push_back(list.substr(begin, comma - begin));
    begin = comma + 1;
  }
}

// Stores `node` into `config.*member`; returns what is wrong with its type, if anything.
std::string assign(GatewayConfig& config, const ConfigKey::Member& member, const YAML::Node& node) {
  struct Visitor {
    GatewayConfig& config;
    const YAML::Node& node;

    std::string operator()(std::string GatewayConfig::*target) const {
      if (!node.IsScalar()) return "expected a single value";
      config.*target = node.Scalar();
      return {};
    }
    std::string operator()(std::vector<std::string> GatewayConfig::*target) const {
      auto& items = config.*target;
      items.clear();
      if (node.IsScalar()) {
        split_into(node.Scalar(), items);
        return {};
      }
      if (!node.IsSequence()) return "expected a list or a comma-separated value";
      for (const YAML::Node& item : node) {
        if (!item.IsScalar()) return "list items must be single values";
        items.push_back(item.Scalar());
      }
      return {};
    }
    std::string operator()(int GatewayConfig::*target) const {
      return node.IsScalar() ? read_number(node, config.*target) : "expected an integer";
    }
    std::string operator()(double GatewayConfig::*target) const {
      return node.IsScalar() ? read_number(node, config.*target) : "expected a number";
    }
    std::string operator()(bool GatewayConfig::*target) const {
      if (node.IsScalar() && (node.Scalar() == "true" || node.Scalar() == "false")) {
        config.*target = node.Scalar() == "true";
        return {};
      }
      return "expected true or false";
    }
  };
  return std::visit(Visitor{config, node}, member);
}

int line_of(const YAML::Mark& mark) { return mark.is_null() ? 0 : mark.line + 1; }

// "topic robot": a key, a space and a value, the ':' forgotten: the hint, when the first word is a
// key (or nearly one).
std::optional<std::string> missing_colon_hint(const std::string& text) {
  const auto space = text.find_first_of(" \t");
  if (space == std::string::npos || space == 0) return std::nullopt;
  const std::string word = text.substr(0, space);
  const ConfigKey* key = find_key(word);
  const std::optional<std::string_view> nearest = key ? std::optional(key->name) : nearest_key(word);
  if (!nearest) return std::nullopt;
  return "not a 'key: value' line (a missing ':' after '" + std::string(*nearest) + "'?)";
}

}  // namespace

std::span<const ConfigKey> config_keys() { return kKeys; }

ConfigResult parse_gateway_config(std::string_view yaml_text, const GatewayConfig& defaults) {
  try {
    const YAML::Node root = YAML::Load(std::string(yaml_text));
    GatewayConfig config = defaults;
    if (root.IsNull()) return config;  // an empty file: nothing to change
    if (!root.IsMap()) {
      if (root.IsScalar())
        if (auto hint = missing_colon_hint(root.Scalar()))
          return ConfigError{line_of(root.Mark()), std::move(*hint)};
      return ConfigError{line_of(root.Mark()), "expected a mapping of 'key: value' lines"};
    }

    // Each key's check runs once the whole file is read: a check that reads another key (pcap-ring
    // against expected-rate) must see that key's value from the file whatever the order of the lines.
    std::set<std::string, std::less<>> seen;
    std::vector<std::pair<const ConfigKey*, int>> given;  // in file order, with their lines
    for (const auto& entry : root) {
      const int line = line_of(entry.first.Mark());
      if (!entry.first.IsScalar()) return ConfigError{line, "keys must be plain names"};
      const std::string& name = entry.first.Scalar();
      const ConfigKey* key = find_key(name);
      if (!key) {
        // "topic robot" on the last line is read as a key without a value, not as an error.
        if (auto hint = missing_colon_hint(name)) return ConfigError{line, std::move(*hint)};
        if (const auto nearest = nearest_key(name))
          return ConfigError{line,
                             "unknown key '" + name + "': did you mean '" + std::string(*nearest) + "'?"};
        return ConfigError{line, "unknown key '" + name + "' (known: " + known_keys() + ")"};
      }
      if (!seen.insert(name).second) return ConfigError{line, "'" + name + "' is given twice"};
      if (entry.second.IsNull()) return ConfigError{line, name + ": has no value"};
      if (auto error = assign(config, key->member, entry.second); !error.empty())
        return ConfigError{line, name + ": " + error};
      given.emplace_back(key, line);
    }
    // An instance's partition (instance_defaults) is a default a ROS 2 file does not want: ROS 2
    // tells robots apart by namespace, so `ros2: true` without a `partition:` line drops it.
    if (config.ros2 && !seen.contains("partition") && config.partition == defaults.partition)
      config.partition.clear();
    for (const auto& [key, line] : given)
      if (auto error = key->check(config); !error.empty())
        return ConfigError{line, std::string(key->name) + ": " + error};
    return config;
  } catch (const YAML::Exception& error) {
    const int line = line_of(error.mark);
    if (const int missing_colon = line > 0 ? line_without_colon(yaml_text, line) : 0; missing_colon > 0)
      return ConfigError{missing_colon, "not a 'key: value' line (a missing ':' after the key?)"};
    return ConfigError{line, error.msg};
  } catch (const std::exception& error) {  // e.g. std::bad_alloc from a huge document
    return ConfigError{0, error.what()};
  }
}

std::string log_level_name(const GatewayConfig& config) { return lowercase(config.log_level); }

std::optional<std::string_view> nearest_key(std::string_view name) {
  // "stats_file", "Stats-File": the spelling of the flags differs only in case and '-'.
  std::string normalized = lowercase(std::string(name));
  std::ranges::replace(normalized, '_', '-');
  const ConfigKey* best = nullptr;
  std::size_t best_distance = 0;
  for (const ConfigKey& key : kKeys) {
    const std::size_t distance = edit_distance(normalized, key.name);
    if (best == nullptr || distance < best_distance) {
      best = &key;
      best_distance = distance;
    }
  }
  // A third of the name may be wrong ("lissten", "expected_rates"), never a different word.
  if (best == nullptr || best_distance > std::max<std::size_t>(1, best->name.size() / 3)) return std::nullopt;
  return best->name;
}

std::variant<GatewayConfig, std::string> instance_defaults(std::string_view name) {
  if (name.empty() || name == "." || name == ".." || name.find('/') != std::string_view::npos)
    return "--instance: '" + std::string(name) + "' cannot name a directory (rsg-gateway@NAME's NAME)";
  GatewayConfig defaults;
  defaults.partition = name;
  defaults.stats_file = std::string(kUnitRuntimeRoot) + "/" + std::string(name) + "/stats.json";
  defaults.pcap_dir = std::string(kUnitStateRoot) + "/" + std::string(name);
  return defaults;
}

std::optional<std::string_view> unit_directory_kind(std::string_view dir) {
  while (dir.size() > 1 && dir.ends_with('/')) dir.remove_suffix(1);
  // One component below the root: what RuntimeDirectory=rsg/%i and StateDirectory=rsg/%i create.
  const auto below = [dir](std::string_view root) {
    if (!dir.starts_with(root) || dir.size() <= root.size() + 1 || dir[root.size()] != '/') return false;
    const std::string_view name = dir.substr(root.size() + 1);
    return name != "." && name != ".." && name.find('/') == std::string_view::npos;
  };
  if (below(kUnitRuntimeRoot)) return "RuntimeDirectory=";
  if (below(kUnitStateRoot)) return "StateDirectory=";
  return std::nullopt;
}

std::optional<std::string> check_config(const GatewayConfig& config) {
  for (const ConfigKey& key : kKeys)
    if (auto error = key.check(config); !error.empty()) return "--" + std::string(key.name) + ": " + error;

  if (!config.has_ingress() && !config.has_egress())
    return "nothing to do: give --listen (raw -> DDS) and/or --egress-topic with --send-to (DDS -> raw)";
  if (config.has_egress() && config.send_to.empty()) return "--egress-topic needs at least one --send-to";
  if (!config.has_egress() && !config.send_to.empty()) return "--send-to needs --egress-topic (or --ros2)";
  if (config.requests_selection() && !config.has_ingress())
    return "--request-groups/--request-fields need --listen: the robot answers to the listening socket";
  if (!config.robot.empty() && !config.requests_selection())
    return "--robot needs --request-groups or --request-fields";
  if (!config.allow_from.empty() && !config.has_ingress()) return "--allow-from needs --listen";
  if (config.pcap_ring > 0 && config.pcap_dir.empty()) return "--pcap-ring needs --pcap-dir";
  if ((!config.joint_states.empty() || !config.tf.empty() || !config.external_wrench.empty()) &&
      !config.has_ingress())
    return "--joint-states/--tf/--external-wrench need --listen: they come from the received frames";
  if (config.pcap_ring > 0 && !config.has_ingress())
    return "--pcap-ring needs --listen: it records what arrives there";
  return std::nullopt;
}

std::optional<RateTopic> parse_rate_topic(const std::string& value) {
  // The rate follows the first colon after which the rest reads as one, so "a:every:5" is `a` every
  // 5th frame (not `a:every` at 5 Hz) while a NAME may still hold colons of its own.
  if (value.starts_with(':')) return std::nullopt;  // no NAME
  for (std::size_t colon = value.find(':'); colon != std::string::npos; colon = value.find(':', colon + 1)) {
    if (const auto decimation = parse_decimation(value.substr(colon + 1)))
      return RateTopic{value.substr(0, colon), *decimation};
  }
  return std::nullopt;
}

std::optional<Decimation> parse_decimation(const std::string& value) {
  constexpr std::string_view kEvery = "every:";
  if (value.starts_with(kEvery)) {
    const std::string_view n = std::string_view(value).substr(kEvery.size());
    const std::optional<std::uint32_t> every = wire::internal::parse_number<std::uint32_t>(n);
    if (!every || *every < 1 || *every > 1'000'000) return std::nullopt;
    return Decimation{*every, {}};
  }
  const std::optional<double> hz = wire::internal::parse_number<double>(value);
  if (!hz || !(*hz > 0 && *hz <= 10000)) return std::nullopt;
  return Decimation{0, std::chrono::nanoseconds(static_cast<std::int64_t>(1e9 / *hz))};
}

wire::Selection requested_selection(const GatewayConfig& config) {
  // Both lists were checked with the configuration.
  wire::Selection selection;
  if (!config.request_groups.empty()) selection = *wire::parse_group_list(join(config.request_groups));
  if (!config.request_fields.empty()) {
    const wire::Selection fields = *wire::parse_field_list(join(config.request_fields));
    for (const wire::FieldInfo& field : wire::kFields)
      if (fields.contains(field.id())) selection.add(field.id());
  }
  return selection;
}

}  // namespace rsg::gateway
