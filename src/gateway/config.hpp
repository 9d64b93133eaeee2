// The gateway's configuration: one table of keys serves the command line (`--KEY VALUE`) and the
// YAML file (`KEY: VALUE`), so both always accept the same names, types and checks.
//
//   listen: 0.0.0.0:5000
//   allow-from: [192.168.1.0/24, "fd00::/8"]
//   request-groups: [2, 5]
//
// List keys take a YAML sequence or a comma-separated string, as on the command line.
#pragma once

#include <cstddef>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "gateway/decimator.hpp"
#include "rsg/wire/selection.hpp"

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

  // Downsampled copies of the state: NAME:HZ, each on its own writer (Fast DDS 2.9 has no
  // TIME_BASED_FILTER, so slow readers cannot ask for a rate themselves)
  std::vector<std::string> rate_topics;
  std::vector<std::string> send_to;
  double egress_rate = 0;  ///< egress samples sent per second at most; 0: the expected rate

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
  std::string log_format = "text";  ///< once started: "text" or "json" (journal_log.hpp)
  /// A SIGHUP reload may widen access (gateway.hpp, widened_access); without it such a reload is refused.
  bool reload_widens_access = false;

  // Monitoring: Prometheus metrics and /healthz on HOST:PORT (metrics_server.hpp); "" : off
  std::string metrics;
  std::string name;  ///< the `gateway` label of the metrics; "" : the partition, else the host's name
  int metrics_max_connections = 32;
  int metrics_max_connections_per_client = 8;
  int metrics_header_timeout_ms = 5000;
  int metrics_idle_timeout_ms = 15000;

  // Flight recorder: the last pcap_ring seconds of raw datagrams, dumped into pcap_dir as pcap
  double pcap_ring = 0;  ///< seconds; 0: off
  std::string pcap_dir;
  // Its bounds (docs/configuration.md): an outsider who can flap the link or send a flood cannot
  // make it fill the disk. The defaults are safe to leave running for months.
  double pcap_min_interval = 10;  ///< seconds at least between two dumps, whatever asks; 0: none
  int pcap_max_files = 100;       ///< rsg's dump files kept in pcap_dir, oldest deleted first
  int pcap_max_mb = 500;          ///< and their bytes, MiB
  bool pcap_all_sources = false;  ///< also keep datagrams from outside allow-from in the ring

  // Real-time mode of the ingress thread (src/gateway/realtime.hpp: what each needs)
  int rt_priority = 0;  ///< SCHED_FIFO priority 1..99, with mlockall; 0: off
  int cpu = -1;         ///< pin the ingress thread to this CPU; -1: off

  // ROS 2 naming (docs/ros2.md): rt/<ros2_namespace>/<topic> with rsg_msgs type names,
  // status on gateway_status, egress on robot_state_cmd unless --egress-topic says otherwise
  bool ros2 = false;
  std::string ros2_namespace;  ///< "" or e.g. "/robot1"

  // Standard ROS 2 topics (docs/ros2.md), each off ("") or at a RATE: "HZ" (at most HZ a second)
  // or "every:N" (every Nth frame that carries what the topic needs)
  std::string joint_states;     ///< sensor_msgs/JointState from q, dq, tau_J
  std::string tf;               ///< tf2_msgs/TFMessage base_frame -> ee_frame from O_T_EE
  std::string external_wrench;  ///< geometry_msgs/WrenchStamped from O_F_ext_hat_K
  std::vector<std::string> joint_names = {"panda_joint1", "panda_joint2", "panda_joint3", "panda_joint4",
                                          "panda_joint5", "panda_joint6", "panda_joint7"};
  std::string base_frame = "panda_link0";
  std::string ee_frame = "panda_EE";
  std::string wrench_frame = "panda_link0";  ///< as franka_ros2's state broadcaster: O is link0

  // Fast DDS XML profiles
  std::vector<std::string>
      profiles;  ///< files or directories, loaded in order; empty: default_profiles_dir()
  std::string participant_profile = "rsg_participant";
  std::string writer_profile = "rsg_state_writer";
  std::string reader_profile = "rsg_state_reader";
  std::string status_profile = "rsg_status_writer";
  std::string data_sharing = "auto";  ///< "auto" (as the profiles say) or "off" (gateway/entities.hpp)

  // Discovery without multicast (rsg/dds/discovery.hpp)
  std::vector<std::string> discovery_servers;
  std::vector<std::string> peers;

  bool has_ingress() const { return !listen.empty(); }
  bool has_egress() const { return !egress_topic.empty() || (ros2 && !send_to.empty()); }
  bool requests_selection() const { return !request_groups.empty() || !request_fields.empty(); }
};

/// Upper limits of the values whose product the gateway allocates or walks per datagram at start-up,
/// so that a configuration that cannot run is refused when it is read, not by std::bad_alloc (or a
/// gateway that spends its time in a list) once running. docs/configuration.md, "Limits".
inline constexpr std::size_t kMaxAllowFrom = 256;  ///< networks, each compared with every datagram's source
inline constexpr std::size_t kMaxRateTopics = 32;  ///< each a DDS writer with the state writer's history
inline constexpr std::size_t kMaxSendTo = 64;      ///< egress destinations, one send each per sample
/// pcap-ring × expected-rate: the flight recorder preallocates twice this many datagram slots of
/// wire::kMaxFrameBytes each (120 s at 1 kHz, about 513 MB).
inline constexpr double kMaxFlightRecorderDatagrams = 120000;

/// One configuration key: its name (the long flag without "--" and the YAML key), its help text,
/// the member it sets, and the check its value must pass.
struct ConfigKey {
  using Member = std::variant<std::string GatewayConfig::*, std::vector<std::string> GatewayConfig::*,
                              int GatewayConfig::*, double GatewayConfig::*, bool GatewayConfig::*>;
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
/// each value once the whole document is read (so the order of the lines never matters), not how keys
/// combine (`check_config` does that once flags are merged in). Never
/// throws, touches no files and no network: safe to fuzz.
ConfigResult parse_gateway_config(std::string_view yaml_text, const GatewayConfig& defaults = {});

/// Checks every value and how the keys combine (e.g. `--send-to` needs `--egress-topic`).
/// Returns what is wrong, or nothing.
std::optional<std::string> check_config(const GatewayConfig& config);

/// The directories the systemd unit rsg-gateway@NAME creates at its start (RuntimeDirectory=rsg/%i,
/// StateDirectory=rsg/%i in deploy/systemd/rsg-gateway@.service; deploy.systemd_unit checks that
/// the unit says so): /run/rsg/NAME and /var/lib/rsg/NAME.
inline constexpr std::string_view kUnitRuntimeRoot = "/run/rsg";
inline constexpr std::string_view kUnitStateRoot = "/var/lib/rsg";

/// The defaults of the instance `name` of the unit (`--instance NAME`), under what its file and
/// flags set: partition NAME, stats-file /run/rsg/NAME/stats.json, pcap-dir /var/lib/rsg/NAME. So a
/// copy of robot1.yaml that does not set them runs robot2 in a partition and directories of its own.
/// Returns what is wrong with `name` instead when it cannot be a directory's name.
std::variant<GatewayConfig, std::string> instance_defaults(std::string_view name);

/// Which unit directory `dir` is, when it is one the unit creates at start ("RuntimeDirectory="
/// for /run/rsg/NAME, "StateDirectory=" for /var/lib/rsg/NAME), else nothing.
std::optional<std::string_view> unit_directory_kind(std::string_view dir);

/// The spdlog level name of `log-level` (given in any case: "WARN" is "warn"); assumes a checked config.
std::string log_level_name(const GatewayConfig& config);

/// The key nearest to `name` when it is probably a misspelling of one ("stats_file", "lissten"),
/// else nothing.
std::optional<std::string_view> nearest_key(std::string_view name);

/// One `rate-topic` value "NAME:HZ" or "NAME:every:N" split, or nothing when it is neither.
struct RateTopic {
  std::string name;
  Decimation rate;
};
std::optional<RateTopic> parse_rate_topic(const std::string& value);

/// A RATE of a standard ROS 2 topic ("100", "every:10"), or nothing when it is not one.
std::optional<Decimation> parse_decimation(const std::string& value);

/// The selection `request-groups` and `request-fields` ask for together (assumes a checked config).
wire::Selection requested_selection(const GatewayConfig& config);

}  // namespace rsg::gateway
