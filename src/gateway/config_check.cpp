#include "gateway/config_check.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <cerrno>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "app/dds_options.hpp"
#include "gateway/errno_text.hpp"
#include "gateway/metrics_server.hpp"
#include "rsg/dds/profiles.hpp"
#include "rsg/error.hpp"
#include "rsg/transport/udp_socket.hpp"
#include "rsg/wire/frame.hpp"

namespace rsg::gateway {
namespace {

// What a file a security property names must begin with: a certificate or key is PEM, governance
// and permissions documents are signed S/MIME (openssl smime -sign), or PEM PKCS#7.
bool holds_what_it_must(const std::string& property, const std::string& text) {
  if (property.ends_with(".governance") || property.ends_with(".permissions"))
    return text.find("MIME-Version:") != std::string::npos ||
           text.find("-----BEGIN PKCS7") != std::string::npos;
  return text.find("-----BEGIN ") != std::string::npos;
}

// A directory that the unit creates at start, for the operator to read that it was not required.
std::string created_by_unit(const std::filesystem::path& dir) {
  std::error_code error;
  if (std::filesystem::exists(dir, error)) return "";
  const auto kind = unit_directory_kind(dir.string());
  return kind ? " (" + dir.string() + " does not exist now: the unit creates it with " + std::string(*kind) +
                    " when it starts)"
              : "";
}

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

void check_bindings(const GatewaySetup& setup) {
  if (setup.ingress) (void)transport::UdpSocket::bind(setup.ingress->listen);  // closed at once
  if (setup.metrics) MetricsServer::check_can_listen(*setup.metrics);
}

void check_profile_files(const GatewayConfig& config) {
  constexpr std::string_view kFile = "file://";
  for (const auto& property : profile_participant_qos(config).properties().properties()) {
    const std::string& value = property.value();
    if (!value.starts_with(kFile)) continue;
    const std::filesystem::path path = value.substr(kFile.size());
    const std::string where = "participant profile '" + config.participant_profile + "', property " +
                              property.name() + ": '" + path.string() + "'";
    std::error_code error;
    if (std::filesystem::is_directory(path, error)) throw InputError(where + ": " + errno_text(EISDIR));
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InputError(where + ": " + errno_text(errno));
    // The first 64 KiB: a PEM block or an S/MIME header is at the start, and a wrong file (a
    // device, a huge log) is never read whole.
    std::string text(64 * 1024, '\0');
    in.read(text.data(), static_cast<std::streamsize>(text.size()));
    text.resize(static_cast<std::size_t>(in.gcount()));
    if (!holds_what_it_must(property.name(), text))
      throw InputError(where + ": not " +
                       (property.name().ends_with(".governance") || property.name().ends_with(".permissions")
                            ? "a signed S/MIME document"
                            : "PEM (no '-----BEGIN ' line)"));
  }
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
      line(fmt::format("flight recorder: last {:g} s into {} (a ring of {:.0f} MB){}",
                       recorder->window.count(), recorder->dir.string(),
                       2 * recorder->window.count() * recorder->expected_rate *
                           static_cast<double>(wire::kMaxFrameBytes) / 1e6,
                       created_by_unit(recorder->dir)));
  }
  if (const auto& egress = setup.egress) {
    std::vector<std::string> destinations;
    for (const auto& destination : egress->destinations) destinations.push_back(destination.to_string());
    line(fmt::format("egress: topic '{}' -> UDP {}", egress->topic, fmt::join(destinations, ", ")));
  }
  if (setup.metrics) line("metrics: http://" + setup.metrics->to_string() + "/metrics");
  if (!config.stats_file.empty())
    line("stats file: " + config.stats_file +
         created_by_unit(std::filesystem::path(config.stats_file).parent_path()));
  line("log level: " + log_level_name(config));
  line("configuration OK: the gateway would start with it (nothing was started)");
  return text;
}

}  // namespace rsg::gateway
