#include "gateway/config_check.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <charconv>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <optional>
#include <set>
#include <sstream>
#include <vector>

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

// The pid of the process holding local `port` (a UDP socket, or a listening TCP one), from
// /proc/net and the processes' descriptors; nothing when none is found (e.g. another user's
// process, whose descriptors this one may not read).
std::optional<int> port_holder(std::uint16_t port, bool tcp) {
  constexpr std::array kUdp{"/proc/net/udp", "/proc/net/udp6"};
  constexpr std::array kTcp{"/proc/net/tcp", "/proc/net/tcp6"};
  std::set<std::string> sockets;
  for (const char* table : tcp ? kTcp : kUdp) {
    std::ifstream in(table);
    std::string line;
    std::getline(in, line);  // the header
    while (std::getline(in, line)) {
      std::istringstream fields(line);
      std::string slot, local, remote, state, queues, timer, retransmits, uid, timeout, inode;
      fields >> slot >> local >> remote >> state >> queues >> timer >> retransmits >> uid >> timeout >> inode;
      const auto colon = local.rfind(':');
      if (colon == std::string::npos || inode.empty()) continue;
      // The port in hexadecimal, as the kernel writes it.
      std::uint32_t local_port = 0;
      const std::string hex = local.substr(colon + 1);
      const std::errc status = std::from_chars(hex.data(), hex.data() + hex.size(), local_port, 16).ec;
      if (status != std::errc() || local_port != port || (tcp && state != "0A")) continue;  // 0A: LISTEN
      sockets.insert("socket:[" + inode + "]");
    }
  }
  if (sockets.empty()) return std::nullopt;
  std::error_code error;
  for (const auto& process : std::filesystem::directory_iterator("/proc", error)) {
    const std::string pid = process.path().filename().string();
    if (pid.empty() || !std::all_of(pid.begin(), pid.end(), [](char c) { return c >= '0' && c <= '9'; }))
      continue;
    std::error_code fd_error;
    for (const auto& fd : std::filesystem::directory_iterator(process.path() / "fd", fd_error)) {
      std::error_code link_error;
      if (sockets.contains(std::filesystem::read_symlink(fd.path(), link_error).string()))
        return std::stoi(pid);
    }
  }
  return std::nullopt;
}

// A process's command line, its arguments apart.
std::vector<std::string> command_line(int pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/cmdline", std::ios::binary);
  std::vector<std::string> words;
  for (std::string word; std::getline(in, word, '\0');) words.push_back(word);
  return words;
}

// Whether `words` is an rsg_gateway started with --config `config_file` (the same file).
bool same_gateway(const std::vector<std::string>& words, const std::string& config_file) {
  if (words.empty() || config_file.empty() || std::filesystem::path(words[0]).filename() != "rsg_gateway")
    return false;
  std::error_code error;
  const auto ours = std::filesystem::weakly_canonical(config_file, error);
  for (std::size_t i = 1; i + 1 < words.size(); ++i)
    if (words[i] == "--config" && std::filesystem::weakly_canonical(words[i + 1], error) == ours) return true;
  return false;
}

// The bind of one port: nothing when it binds, a note when the running gateway of this
// configuration holds it, else the start's error with who holds the port.
std::optional<std::string> check_port(const std::function<void()>& bind, std::uint16_t port, bool tcp,
                                      const std::string& what, const std::string& config_file) {
  try {
    bind();
    return std::nullopt;
  } catch (const EnvironmentError& error) {
    const std::optional<int> holder = port_holder(port, tcp);
    if (!holder) throw;
    const std::vector<std::string> words = command_line(*holder);
    if (same_gateway(words, config_file))
      return fmt::format(
          "{} is held by the running rsg_gateway of this configuration (pid {}): a restart stops it "
          "first",
          what, *holder);
    throw EnvironmentError(
        fmt::format("{} (held by pid {}: {})", error.what(), *holder,
                    words.empty() ? std::string("?") : fmt::format("{}", fmt::join(words, " "))));
  }
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

std::vector<std::string> check_bindings(const GatewaySetup& setup, const std::string& config_file) {
  std::vector<std::string> notes;
  if (const auto& ingress = setup.ingress)
    if (auto note =
            check_port([&] { (void)transport::UdpSocket::bind(ingress->listen); },  // closed at once
                       ingress->listen.port(), false, "UDP " + ingress->listen.to_string(), config_file))
      notes.push_back(std::move(*note));
  if (const auto& metrics = setup.metrics)
    if (auto note = check_port([&] { MetricsServer::check_can_listen(*metrics); }, metrics->port(), true,
                               "TCP " + metrics->to_string(), config_file))
      notes.push_back(std::move(*note));
  return notes;
}

void check_profile_files(const GatewayConfig& config) {
  constexpr std::string_view kFile = "file://";
  const auto qos = profile_participant_qos(config);  // held: the loop walks into it
  for (const auto& property : qos.properties().properties()) {
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

std::string describe_setup(const GatewaySetup& setup, const std::string& config_file,
                           const std::vector<std::string>& notes) {
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
  for (const std::string& note : notes) line(note);
  line("configuration OK: the gateway would start with it (nothing was started)");
  return text;
}

}  // namespace rsg::gateway
