// The command-line options every tool that watches a gateway shares (rsg_record, rsg_view): where
// to read (domain, topics, partitions, view, reader QoS), which profiles to load, and discovery.
// A tool's own Options derive from MonitorOptions, so each option is declared and documented once.
#pragma once

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

#include "app/dds_options.hpp"
#include "app/discovery_cli.hpp"
#include "app/monitor_readers.hpp"
#include "rsg/dds/discovery.hpp"
#include "rsg/dds/profiles.hpp"

namespace rsg::app {

struct MonitorOptions {
  int domain = 0;
  std::string topic = "robot_state";
  std::string status_topic = "rsg_gateway_status";
  std::vector<std::string> partitions;
  std::string view_profile;
  std::string qos_profile = dds::kLoggerReaderProfile;  // a watcher misses nothing a reliable writer kept
  std::vector<std::string> profiles;
  std::string participant_profile = "rsg_participant";
  dds::DiscoveryOptions discovery;

  MonitorTopics topics() const { return {topic, status_topic, partitions, view_profile, qos_profile}; }

  /// Loads --profiles and looks up every profile the options name (dds_options.hpp).
  /// @throws rsg::InputError naming the flag of a file or profile that is not there.
  void load_profiles() const {
    load_profile_options(profiles, participant_profile);
    check_profiles({{"--view", NamedProfile::Kind::kDataReader, view_profile},
                    {"--qos", NamedProfile::Kind::kDataReader, qos_profile}});
  }
};

/// `without_status` completes the --status-topic help: what an empty topic name means to the tool.
inline void add_monitor_options(CLI::App& app, MonitorOptions& options, const std::string& without_status) {
  app.add_option("--domain", options.domain, "DDS domain id")
      ->check(CLI::Range(0, 232))
      ->capture_default_str();
  app.add_option("--topic", options.topic, "RobotState topic")->check(dds_name(false))->capture_default_str();
  app.add_option("--status-topic", options.status_topic, "GatewayStatus topic; \"\" " + without_status)
      ->check(dds_name(true))
      ->capture_default_str();
  app.add_option("--partition", options.partitions, "DDS partition (repeatable; default: none)")
      ->check(dds_name(true));
  app.add_option("--view", options.view_profile,
                 "View profile, e.g. view_joints: only samples carrying its groups");
  app.add_option("--qos", options.qos_profile, "Reader QoS profile")->capture_default_str();
  add_profile_options(app, options.profiles, options.participant_profile);
  add_discovery_options(app, options.discovery);
}

}  // namespace rsg::app
