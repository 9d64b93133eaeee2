// rsg_view: subscribes to RobotState (whole or through a view) and GatewayStatus like any DDS
// reader, and serves them on one port: the Foxglove WebSocket protocol for Foxglove, PlotJuggler
// and Lichtblick, and a live page at http://HOST:PORT/ for an operator with no other tool.
//
// A separate process so that the gateway stays lean: a slow browser costs this process at most its
// own bounded queues, never the gateway or the DDS reader.
//
// Exit status: 0 on SIGINT/SIGTERM, 1 when the port cannot be opened or DDS fails, 2 on usage
// errors (including unknown profiles).
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fstream>
#include <optional>
#include <sstream>

#include "app/matched_writers.hpp"
#include "app/monitor_options.hpp"
#include "app/monitor_readers.hpp"
#include "app/recording.hpp"
#include "app/stop_on_signal.hpp"
#include "app/tool_main.hpp"
#include "dds/internal/fastdds_compat.hpp"
#include "rsg/dds/profiles.hpp"
#include "rsg/dds/views.hpp"
#include "rsg/transport/udp_socket.hpp"
#include "tools/view/server.hpp"
#include "tools/view/view_channels.hpp"
#include "tools/view/web_assets.hpp"

namespace {

namespace fdds = eprosima::fastdds::dds;
using rsg::app::StopOnSignal;

using namespace rsg::app;  // the main skeleton and the exit statuses

constexpr auto kWakeUp = std::chrono::milliseconds(20);
constexpr auto kPageRepeat = std::chrono::seconds(1);

struct Options : rsg::app::MonitorOptions {
  std::string listen = "127.0.0.1:8765";
  double page_rate_hz = 30;
  std::string chart_js = RSG_CHART_JS;
  rsg::tools::view::ServerOptions server;
  double handshake_timeout_s = 10, idle_timeout_s = 60, stall_timeout_s = 20;
};

std::chrono::milliseconds milliseconds_of(double seconds) {
  return std::chrono::milliseconds(static_cast<std::int64_t>(seconds * 1000));
}

std::uint64_t now_ns() {
  return static_cast<std::uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                        std::chrono::system_clock::now().time_since_epoch())
                                        .count());
}

rsg::tools::view::Payload payload_of(std::span<const std::uint8_t> bytes) {
  return std::make_shared<const std::vector<std::uint8_t>>(bytes.begin(), bytes.end());
}
rsg::tools::view::Payload payload_of(const std::string& text) {
  return std::make_shared<const std::vector<std::uint8_t>>(text.begin(), text.end());
}

void add_options(CLI::App& app, Options& options) {
  app.add_option("--listen", options.listen,
                 "HOST:PORT of the WebSocket and HTTP server (0.0.0.0 opens it to other hosts)")
      ->check([](const std::string& text) {
        return rsg::transport::parse_host_port(text, rsg::transport::HostPortRule::kBindAddress).error();
      })
      ->capture_default_str();
  rsg::app::add_monitor_options(app, options, "serves none");
  rsg::app::add_log_level_option(app);
  app.add_option("--max-clients", options.server.max_clients, "WebSocket clients served at once")
      ->check(CLI::Range(1, 1024))
      ->capture_default_str();
  app.add_option("--max-clients-per-address", options.server.max_clients_per_address,
                 "WebSocket clients served at once per client IP address, so that a few addresses cannot "
                 "hold every place of --max-clients")
      ->check(CLI::Range(1, 1024))
      ->capture_default_str();
  app.add_option("--max-connections", options.server.max_connections,
                 "TCP connections (HTTP and WebSocket) open at once; at the limit the oldest one that only "
                 "waits (for a request, or a client with no subscription) makes room, else the new one is "
                 "closed")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  app.add_option("--max-connections-per-address", options.server.max_connections_per_address,
                 "The same per client IP address")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  app.add_option("--max-subscriptions", options.server.max_subscriptions,
                 "Subscriptions per client; more are refused with an error status")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  app.add_option("--max-client-buffer", options.server.max_client_buffer,
                 "Bytes queued for one client; a client over it is closed")
      ->check(CLI::Range(std::size_t{1024}, std::size_t{1} << 34))
      ->capture_default_str();
  app.add_option("--handshake-timeout", options.handshake_timeout_s,
                 "Seconds a connection has to send a whole HTTP request (a WebSocket upgrade too) and finish "
                 "the WebSocket handshake")
      ->check(CLI::Range(0.01, 3600.0))
      ->capture_default_str();
  app.add_option("--idle-timeout", options.idle_timeout_s,
                 "Seconds a WebSocket client may stay without a subscription, or without answering a ping")
      ->check(CLI::Range(0.01, 86400.0))
      ->capture_default_str();
  app.add_option("--stall-timeout", options.stall_timeout_s,
                 "Seconds a client may take none of its messages before it is closed")
      ->check(CLI::Range(0.01, 86400.0))
      ->capture_default_str();
  app.add_option("--queue-depth", options.server.queue_depth,
                 "Messages queued per client and subscription; a slower client loses its oldest")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  app.add_option("--page-rate", options.page_rate_hz, "Updates per second of the page's summary channel")
      ->check(CLI::Range(1.0, 1000.0))
      ->capture_default_str();
  app.add_option(
         "--chart-js", options.chart_js,
         "Chart.js file the page loads (Debian's libjs-chart.js; when the default is missing, the page "
         "shows numbers but no plots)")
      ->check(CLI::ExistingFile)  // checked when given: a file named on purpose must be there
      ->capture_default_str();
}

std::vector<rsg::tools::view::WebFile> web_files(const Options& options) {
  std::vector<rsg::tools::view::WebFile> files{
      {"/", "text/html; charset=utf-8", std::string(rsg::tools::view::web::kIndexHtml)},
      {"/app.js", "text/javascript; charset=utf-8", std::string(rsg::tools::view::web::kAppJs)},
  };
  std::ifstream in(options.chart_js, std::ios::binary);
  if (!in) {
    spdlog::warn(
        "cannot read {} (install libjs-chart.js or pass --chart-js): the page shows numbers but no plots",
        options.chart_js);
    return files;
  }
  std::ostringstream body;
  body << in.rdbuf();
  files.push_back({"/chart.js", "text/javascript; charset=utf-8", body.str()});
  return files;
}

void split_listen(const std::string& text, rsg::tools::view::ServerOptions& server) {
  const rsg::transport::Endpoint endpoint = rsg::transport::Endpoint::parse(text);  // throws rsg::InputError
  std::string host = endpoint.to_string();
  host.resize(host.rfind(':'));
  if (host.size() >= 2 && host.front() == '[') host = host.substr(1, host.size() - 2);
  server.host = host;
  server.port = endpoint.port();
}

int run(const Options& options) {
  rsg::tools::view::ChannelSet channels(options.topic, options.status_topic);
  rsg::tools::view::Server server(options.server, channels.channels(), web_files(options));
  spdlog::info("serving ws://{0}:{1} and http://{0}:{1}/", options.server.host, server.port());

  rsg::dds::WriterDirectory writers;  // what discovery shows, should no writer match
  rsg::dds::Participant participant(options.domain, options.participant_profile, options.discovery,
                                    writers.listener());
  rsg::app::MonitorReaders readers(participant, options.topics());
  StopOnSignal stop_on_signal([&readers] { readers.request_stop(); });

  const auto page_period = std::chrono::duration_cast<std::chrono::steady_clock::duration>(
      std::chrono::duration<double>(1.0 / options.page_rate_hz));
  auto next_page = std::chrono::steady_clock::now();
  rsg::app::CdrSerializer serializer;
  rsg::tools::view::PageSummary summary;
  rsg::RobotState state;
  rsg::GatewayStatus status;
  fdds::SampleInfo info;
  bool summary_pending = false;
  rsg::app::MatchedWriters matched_writers(options.topic, writers, options.domain);
  while (!readers.stop_requested()) {
    readers.wait(kWakeUp);
    matched_writers.update(readers.state());
    while (readers.state().take_next_sample(&state, &info) == rsg::dds::kOk) {
      if (!info.valid_data) continue;
      matched_writers.on_sample();
      const std::uint64_t time = now_ns();
      const auto cdr = payload_of(serializer.serialize(state));
      for (const auto channel : channels.robot_state_cdr()) server.publish(channel, time, cdr);
      if (const auto transform = rsg::tools::view::frame_transform_json(state, time))
        server.publish(channels.transform(), time, payload_of(*transform));
      summary.add(state);
      summary_pending = true;
    }
    while (readers.status() != nullptr &&
           readers.status()->take_next_sample(&status, &info) == rsg::dds::kOk) {
      if (!info.valid_data) continue;
      const std::uint64_t time = now_ns();
      const auto cdr = payload_of(serializer.serialize(status));
      for (const auto channel : channels.status_cdr()) server.publish(channel, time, cdr);
      server.publish(channels.status_json(), time, payload_of(rsg::tools::view::status_json(status)));
    }
    // Also once a second when nothing arrives, so that a page opened after the stream stopped shows
    // its last state.
    const auto now = std::chrono::steady_clock::now();
    if ((summary_pending && now >= next_page) || (summary.samples() > 0 && now >= next_page + kPageRepeat)) {
      next_page = now + page_period;
      summary_pending = false;
      server.publish(channels.summary(), now_ns(), payload_of(summary.json(server.dropped())));
    }
  }
  spdlog::info("received {} states; dropped {} messages for slow clients", summary.samples(),
               server.dropped());
  const auto limits = server.limit_counts();
  std::string limit_text;
  for (std::size_t i = 0; i < limits.size(); ++i)
    limit_text +=
        fmt::format("{}{} {}", i == 0 ? "" : ", ", rsg::tools::view::Server::kLimitNames[i], limits[i]);
  spdlog::info("limits: {}", limit_text);
  const auto counts = server.channel_counts();  // in the order of channels.channels()
  for (std::size_t i = 0; i < counts.size(); ++i) {
    const auto& channel = channels.channels()[i];
    spdlog::info("channel {} {} ({}, {}): published {}, dropped {}", channel.id, channel.topic,
                 channel.schema_name, channel.schema_encoding, counts[i].published, counts[i].dropped);
  }
  return kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  rsg::app::init_logging("rsg_view");
  StopOnSignal::block_stop_signals();  // before Fast DDS starts threads (stop_on_signal.hpp)
  CLI::App app{"Serves RobotState and GatewayStatus to Foxglove, PlotJuggler and a live web page.",
               "rsg_view"};
  app.footer(
      "Exit status: 0 on SIGINT/SIGTERM, 1 when the port cannot be opened or DDS fails, 2 usage error.");
  Options options;
  add_options(app, options);
  return run_main(app, argc, argv, [&] {
    options.server.handshake_timeout = milliseconds_of(options.handshake_timeout_s);
    options.server.idle_timeout = milliseconds_of(options.idle_timeout_s);
    options.server.stall_timeout = milliseconds_of(options.stall_timeout_s);
    split_listen(options.listen, options.server);  // the syntax is checked: a name that does not resolve
    options.load_profiles();
    return run(options);
  });
}
