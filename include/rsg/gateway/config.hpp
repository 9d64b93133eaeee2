// The gateway's configuration: one table of keys serves the command line (`--KEY VALUE`) and the
// YAML file (`KEY: VALUE`), so both always accept the same names, types and checks.
//
//   listen: 0.0.0.0:5000
//   allow-from: [192.168.1.0/24, "fd00::/8"]
//   request-groups: [2, 5]
//
// List keys take a YAML sequence or a comma-separated string, as on the command line.
#pragma once

#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "rsg/selection.hpp"

namespace rsg::gateway {

struct GatewayConfig {
  // Ingress: raw frames -> DDS
  std::string listen;
  std::vector<std::string> allow_from;
  std::string topic = "robot_state";
  int domain = 0;
  std::string partition;
  int receive_buffer = 4 << 20;  ///< kernel socket buffer: 2 s of full frames at 1 kHz

  // Egress: DDS -> raw frames
  std::string egress_topic;
  std::vector<std::string> send_to;

  // Selection request to the robot
  std::string robot;
  std::vector<std::string> request_groups;
  std::vector<std::string> request_fields;

  // Status and link supervision
  std::string status_topic = "rsg_gateway_status";
  double expected_rate = 1000;
  int restart_threshold_ms = 100;
  std::string stats_file;
  std::string log_level = "info";

  // Real-time mode of the ingress thread (rsg/gateway/realtime.hpp: what each needs)
  int rt_priority = 0;  ///< SCHED_FIFO priority 1..99, with mlockall; 0: off
  int cpu = -1;         ///< pin the ingress thread to this CPU; -1: off

  // Fast DDS XML profiles
  std::string profiles;  ///< empty: rsg::default_profiles_dir()
  std::string participant_profile = "rsg_participant";
  std::string writer_profile = "rsg_state_writer";
  std::string reader_profile = "rsg_state_reader";
  std::string status_profile = "rsg_status_writer";

  bool has_ingress() const { return !listen.empty(); }
  bool has_egress() const { return !egress_topic.empty(); }
  bool requests_selection() const { return !request_groups.empty() || !request_fields.empty(); }
};

/// One configuration key: its name (the long flag without "--" and the YAML key), its help text,
/// the member it sets, and the check its value must pass.
struct ConfigKey {
  using Member = std::variant<std::string GatewayConfig::*, std::vector<std::string> GatewayConfig::*,
                              int GatewayConfig::*, double GatewayConfig::*>;
  std::string_view name;
  std::string_view help;
  Member member;
  /// Empty when the key's value in `config` is acceptable, else what is wrong with it.
  std::string (*check)(const GatewayConfig& config);
};

/// Every key, in the order `--help` lists them.
std::span<const ConfigKey> config_keys();

struct ConfigError {
  int line = 0;  ///< 1-based line in the YAML text, 0 when the problem is not on one line
  std::string message;
};

/// A configuration or the first problem found in it.
class ConfigResult {
 public:
  ConfigResult(GatewayConfig config) : config_(std::move(config)) {}
  ConfigResult(ConfigError error) : error_(std::move(error)) {}

  explicit operator bool() const { return config_.has_value(); }
  const GatewayConfig& config() const { return *config_; }
  const ConfigError& error() const { return error_; }

 private:
  std::optional<GatewayConfig> config_;
  ConfigError error_;
};

/// Parses a YAML configuration (a mapping of config keys) on top of `defaults`. Checks types and
/// each value, not how keys combine (`check_config` does that once flags are merged in). Never
/// throws, touches no files and no network: safe to fuzz.
ConfigResult parse_gateway_config(std::string_view yaml_text, const GatewayConfig& defaults = {});

/// Checks every value and how the keys combine (e.g. `--send-to` needs `--egress-topic`).
/// Returns what is wrong, or nothing.
std::optional<std::string> check_config(const GatewayConfig& config);

/// The selection `request-groups` and `request-fields` ask for together (assumes a checked config).
Selection requested_selection(const GatewayConfig& config);

}  // namespace rsg::gateway
