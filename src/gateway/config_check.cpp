#include "gateway/config_check.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "app/dds_options.hpp"
#include "rsg/dds/profiles.hpp"
#include "rsg/wire/frame.hpp"

namespace rsg::gateway {
namespace {

std::string profiles_text(const GatewayConfig& config) {
  return config.profiles.empty() ? dds::default_profiles_dir().string()
                                 : fmt::format("{}", fmt::join(config.profiles, ", "));
}

}  // namespace

void check_entity_profiles_offline(const GatewayConfig& config) {
  using Kind = app::NamedProfile::Kind;
  app::check_profiles(
      {{"--status-profile", Kind::kDataWriter, config.status_profile},
       {"--writer-profile", Kind::kDataWriter, config.has_ingress() ? config.writer_profile : ""},
       {"--reader-profile", Kind::kDataReader, config.has_egress() ? config.reader_profile : ""}});
}

std::string describe_setup(const GatewaySetup& setup, const std::string& config_file) {
  const GatewayConfig& config = setup.config;
  std::string text;
  const auto line = [&text](const std::string& item) { text += item + "\n"; };
  line(config_file.empty() ? "configuration: flags only"
                           : "configuration: " + config_file + " and the flags");
  line(fmt::format("DDS: domain {}, partition {}{}", config.domain,
                   config.partition.empty() ? "(none)" : "'" + config.partition + "'",
                   config.ros2
                       ? ", ROS 2 naming" +
                             (config.ros2_namespace.empty() ? std::string() : " in " + config.ros2_namespace)
                       : std::string()));
  line(fmt::format("profiles: {} (participant '{}', status writer '{}'{}{})", profiles_text(config),
                   config.participant_profile, config.status_profile,
                   setup.ingress ? ", state writer '" + config.writer_profile + "'" : std::string(),
                   setup.egress ? ", egress reader '" + config.reader_profile + "'" : std::string()));
  if (const auto& ingress = setup.ingress) {
    line(fmt::format("ingress: UDP {} -> topic '{}', expecting {:g} Hz, from {}", ingress->listen.to_string(),
                     ingress->topic, config.expected_rate,
                     config.allow_from.empty() ? std::string("anyone")
                                               : fmt::format("{}", fmt::join(config.allow_from, ", "))));
    for (const auto& rate : ingress->rate_topics) line("rate topic: '" + rate.topic + "'");
    if (ingress->requested_selection)
      line("selection request to " +
           (ingress->robot ? ingress->robot->to_string() : std::string("the frames' source")));
    if (const auto& recorder = ingress->flight_recorder)
      line(fmt::format("flight recorder: last {:g} s into {} (a ring of {:.0f} MB)", recorder->window.count(),
                       recorder->dir.string(),
                       2 * recorder->window.count() * recorder->expected_rate *
                           static_cast<double>(wire::kMaxFrameBytes) / 1e6));
  }
  if (const auto& egress = setup.egress) {
    std::vector<std::string> destinations;
    for (const auto& destination : egress->destinations) destinations.push_back(destination.to_string());
    line(fmt::format("egress: topic '{}' -> UDP {}", egress->topic, fmt::join(destinations, ", ")));
  }
  if (setup.metrics) line("metrics: http://" + setup.metrics->to_string() + "/metrics");
  if (!config.stats_file.empty()) line("stats file: " + config.stats_file);
  line("log level: " + log_level_name(config));
  line("configuration OK: the gateway would start with it (nothing was started)");
  return text;
}

}  // namespace rsg::gateway
