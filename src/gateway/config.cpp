#include "rsg/gateway/config.hpp"

#include <sched.h>
#include <yaml-cpp/yaml.h>

#include <array>
#include <charconv>
#include <set>

#include "rsg/gateway/source_filter.hpp"

namespace rsg::gateway {
namespace {

std::string join(const std::vector<std::string>& items) {
  std::string joined;
  for (const auto& item : items) joined += (joined.empty() ? "" : ",") + item;
  return joined;
}

// Syntax only: "HOST:PORT" or "[V6]:PORT". Names are resolved when the gateway starts, not here,
// so parsing a configuration never touches the network.
std::string check_host_port(const std::string& value, bool allow_port_zero) {
  const std::size_t colon = value.rfind(':');
  if (colon == std::string::npos || colon == 0) return "'" + value + "' is not HOST:PORT";
  const std::string_view port = std::string_view(value).substr(colon + 1);
  unsigned number = 0;
  const auto [end, status] = std::from_chars(port.data(), port.data() + port.size(), number);
  if (port.empty() || status != std::errc() || end != port.data() + port.size() || number > 65535 ||
      (number == 0 && !allow_port_zero))
    return "'" + value + "': port must be a number " + (allow_port_zero ? "0" : "1") + "..65535";
  return {};
}

std::string check_optional_host_port(const std::string& value) {
  return value.empty() ? std::string() : check_host_port(value, false);
}

std::string check_not_empty(const std::string& value) { return value.empty() ? "must not be empty" : ""; }

const std::array kKeys = {
    ConfigKey{"listen", "Receive raw frames on HOST:PORT (UDP) and publish them", &GatewayConfig::listen,
              [](const GatewayConfig& c) { return c.listen.empty() ? "" : check_host_port(c.listen, true); }},
    ConfigKey{"allow-from", "Accept frames only from ADDR[/PREFIX] (repeatable; IPv4 or IPv6)",
              &GatewayConfig::allow_from,
              [](const GatewayConfig& c) {
                std::string error;
                for (const auto& network : c.allow_from)
                  if (!is_valid_network(network, error)) return error;
                return std::string();
              }},
    ConfigKey{"topic", "Topic the received frames are published on", &GatewayConfig::topic,
              [](const GatewayConfig& c) { return check_not_empty(c.topic); }},
    ConfigKey{"domain", "DDS domain id", &GatewayConfig::domain,
              [](const GatewayConfig& c) {
                return c.domain >= 0 && c.domain <= 232 ? "" : std::to_string(c.domain) + " is not in 0..232";
              }},
    ConfigKey{"partition", "DDS partition of every topic (default: none)", &GatewayConfig::partition,
              [](const GatewayConfig&) { return std::string(); }},
    ConfigKey{
        "receive-buffer", "Kernel UDP receive buffer, bytes", &GatewayConfig::receive_buffer,
        [](const GatewayConfig& c) { return c.receive_buffer >= 0 ? "" : std::string("must be >= 0"); }},
    ConfigKey{"egress-topic", "Send the samples of this topic as raw frames to --send-to",
              &GatewayConfig::egress_topic, [](const GatewayConfig&) { return std::string(); }},
    ConfigKey{"send-to", "Destination HOST:PORT of egress frames (repeatable)", &GatewayConfig::send_to,
              [](const GatewayConfig& c) {
                for (const auto& destination : c.send_to)
                  if (auto error = check_host_port(destination, false); !error.empty()) return error;
                return std::string();
              }},
    ConfigKey{
        "robot", "HOST:PORT the selection request goes to (default: wherever frames come from, once they do)",
        &GatewayConfig::robot, [](const GatewayConfig& c) { return check_optional_host_port(c.robot); }},
    ConfigKey{"request-groups", "Ask the robot for these groups, e.g. 2,5", &GatewayConfig::request_groups,
              [](const GatewayConfig& c) {
                Selection ignored;
                std::string error;
                return c.request_groups.empty() || parse_group_list(join(c.request_groups), ignored, error)
                           ? std::string()
                           : error;
              }},
    ConfigKey{"request-fields", "Ask the robot for these fields, e.g. q,dq,time",
              &GatewayConfig::request_fields,
              [](const GatewayConfig& c) {
                Selection ignored;
                std::string error;
                return c.request_fields.empty() || parse_field_list(join(c.request_fields), ignored, error)
                           ? std::string()
                           : error;
              }},
    ConfigKey{"status-topic", "Topic of the GatewayStatus samples", &GatewayConfig::status_topic,
              [](const GatewayConfig& c) { return check_not_empty(c.status_topic); }},
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
    ConfigKey{"log-level", "trace, debug, info, warn, error or off", &GatewayConfig::log_level,
              [](const GatewayConfig& c) {
                static constexpr std::array kLevels = {"trace", "debug", "info", "warn", "error", "off"};
                for (const char* level : kLevels)
                  if (c.log_level == level) return std::string();
                return "'" + c.log_level + "' is not one of trace, debug, info, warn, error, off";
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
    ConfigKey{"profiles", "Fast DDS XML profile file or directory (default: rsg's xml_profiles)",
              &GatewayConfig::profiles, [](const GatewayConfig&) { return std::string(); }},
    ConfigKey{"participant-profile", "XML participant profile", &GatewayConfig::participant_profile,
              [](const GatewayConfig& c) { return check_not_empty(c.participant_profile); }},
    ConfigKey{"writer-profile", "XML data writer profile of the state topic", &GatewayConfig::writer_profile,
              [](const GatewayConfig& c) { return check_not_empty(c.writer_profile); }},
    ConfigKey{"reader-profile", "XML data reader profile of the egress topic", &GatewayConfig::reader_profile,
              [](const GatewayConfig& c) { return check_not_empty(c.reader_profile); }},
    ConfigKey{"status-profile", "XML data writer profile of the status topic", &GatewayConfig::status_profile,
              [](const GatewayConfig& c) { return check_not_empty(c.status_profile); }},
};

const ConfigKey* find_key(std::string_view name) {
  for (const ConfigKey& key : kKeys)
    if (key.name == name) return &key;
  return nullptr;
}

std::string known_keys() {
  std::string names;
  for (const ConfigKey& key : kKeys) names += (names.empty() ? "" : ", ") + std::string(key.name);
  return names;
}

template <class Number>
std::string read_number(const YAML::Node& node, Number& out) {
  const std::string& text = node.Scalar();
  const auto [end, status] = std::from_chars(text.data(), text.data() + text.size(), out);
  if (text.empty() || status != std::errc() || end != text.data() + text.size())
    return "'" + text + "' is not " + (std::is_integral_v<Number> ? "an integer" : "a number");
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
  };
  return std::visit(Visitor{config, node}, member);
}

int line_of(const YAML::Mark& mark) { return mark.is_null() ? 0 : mark.line + 1; }

}  // namespace

std::span<const ConfigKey> config_keys() { return kKeys; }

ConfigResult parse_gateway_config(std::string_view yaml_text, const GatewayConfig& defaults) {
  try {
    const YAML::Node root = YAML::Load(std::string(yaml_text));
    GatewayConfig config = defaults;
    if (root.IsNull()) return config;  // an empty file: nothing to change
    if (!root.IsMap()) return ConfigError{line_of(root.Mark()), "expected a mapping of 'key: value' lines"};

    std::set<std::string, std::less<>> seen;
    for (const auto& entry : root) {
      const int line = line_of(entry.first.Mark());
      if (!entry.first.IsScalar()) return ConfigError{line, "keys must be plain names"};
      const std::string& name = entry.first.Scalar();
      const ConfigKey* key = find_key(name);
      if (!key) return ConfigError{line, "unknown key '" + name + "' (known: " + known_keys() + ")"};
      if (!seen.insert(name).second) return ConfigError{line, "'" + name + "' is given twice"};
      if (entry.second.IsNull()) return ConfigError{line, name + ": has no value"};
      if (auto error = assign(config, key->member, entry.second); !error.empty())
        return ConfigError{line, name + ": " + error};
      if (auto error = key->check(config); !error.empty()) return ConfigError{line, name + ": " + error};
    }
    return config;
  } catch (const YAML::Exception& error) {
    return ConfigError{line_of(error.mark), error.msg};
  } catch (const std::exception& error) {  // e.g. std::bad_alloc from a huge document
    return ConfigError{0, error.what()};
  }
}

std::optional<std::string> check_config(const GatewayConfig& config) {
  for (const ConfigKey& key : kKeys)
    if (auto error = key.check(config); !error.empty()) return "--" + std::string(key.name) + ": " + error;

  if (!config.has_ingress() && !config.has_egress())
    return "nothing to do: give --listen (raw -> DDS) and/or --egress-topic with --send-to (DDS -> raw)";
  if (config.has_egress() && config.send_to.empty()) return "--egress-topic needs at least one --send-to";
  if (!config.has_egress() && !config.send_to.empty()) return "--send-to needs --egress-topic";
  if (config.requests_selection() && !config.has_ingress())
    return "--request-groups/--request-fields need --listen: the robot answers to the listening socket";
  if (!config.robot.empty() && !config.requests_selection())
    return "--robot needs --request-groups or --request-fields";
  if (!config.allow_from.empty() && !config.has_ingress()) return "--allow-from needs --listen";
  return std::nullopt;
}

Selection requested_selection(const GatewayConfig& config) {
  Selection selection;
  std::string ignored;
  if (!config.request_groups.empty()) parse_group_list(join(config.request_groups), selection, ignored);
  if (!config.request_fields.empty()) {
    Selection fields;
    parse_field_list(join(config.request_fields), fields, ignored);
    for (const FieldInfo& field : kFields)
      if (fields.contains(field.id())) selection.add(field.id());
  }
  return selection;
}

}  // namespace rsg::gateway
