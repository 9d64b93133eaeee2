#include "tests/bench/e2e/scenarios.hpp"

#include <time.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fstream>
#include <iostream>
#include <optional>
#include <regex>
#include <stdexcept>
#include <stop_token>
#include <thread>

#include "rsg/dds/fastdds.hpp"
#include "rsg/gateway/embedded_gateway.hpp"
#include "rsg/transport/udp_socket.hpp"
#include "tests/bench/e2e/child_process.hpp"
#include "tests/bench/e2e/latency_log.hpp"
#include "tests/bench/e2e/process_usage.hpp"
#include "tests/bench/e2e/ros2_standard_readers.hpp"
#include "tests/bench/e2e/stamped_frames.hpp"
#include "tests/bench/e2e/state_subscriber.hpp"
#include "tests/bench/floor/relay_loop.hpp"

namespace rsg::bench {
namespace fdds = eprosima::fastdds::dds;
namespace {

using json = nlohmann::json;
using std::chrono::milliseconds;
using std::chrono::seconds;

// "udp" and "datasharing" run on the shipped participant profile (xml_profiles/rsg.xml: UDP with
// 4 MiB socket buffers; data-sharing needs no SHM transport), so they measure what users get.
// "shm" adds Fast DDS's SHM transport, which rsg's profile leaves out, for comparison;
// "udp_default_buffers" is UDP with the kernel's default socket buffers.
constexpr std::array kTransports = {
    Transport{"udp", "rsg_participant", "bench_reader"},
    Transport{"shm", "bench_shm", "bench_reader"},
    Transport{"datasharing", "rsg_participant", "bench_reader_datasharing"},
    Transport{"udp_default_buffers", "bench_udp", "bench_reader"},
};

// The gateway's own default: 2 s of full frames at 1 kHz. The UDP baseline gets the same.
constexpr int kReceiveBufferBytes = 4 << 20;
// Generous: discovery and start-up on a 2-core machine shared with compilers can take seconds.
constexpr auto kStartupTimeout = seconds(20);
// After the last frame: how long stragglers (retransmissions, a descheduled reader) may take.
constexpr auto kDrainTimeout = seconds(2);
// A rate step counts only when the sender really kept the rate it claims.
constexpr double kMinAchievedRateFraction = 0.95;

/// Frame k of a run is due at start + k / rate. A late frame leaves at once, so the average rate
/// holds when the sender is descheduled; latency starts at each frame's own stamp, so sending
/// late is not counted as latency. Absolute deadlines on CLOCK_MONOTONIC, with the timer slack of
/// the sending thread set to 1 ns in main(): the kernel's default 50 us slack would bunch frames.
class Pacer {
 public:
  explicit Pacer(double rate_hz) : period_ns_(1e9 / rate_hz), start_ns_(monotonic_ns()) {}

  void wait_for(std::uint64_t k) const {
    const std::int64_t due = start_ns_ + std::llround(static_cast<double>(k) * period_ns_);
    const timespec deadline{static_cast<time_t>(due / 1'000'000'000), static_cast<long>(due % 1'000'000'000)};
    while (::clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &deadline, nullptr) == EINTR) {
    }
  }

 private:
  double period_ns_;
  std::int64_t start_ns_;
};

struct SendReport {
  std::uint64_t sent = 0;
  std::uint64_t failed = 0;
  double seconds = 0;
  double achieved_rate_hz() const { return seconds > 0 ? static_cast<double>(sent + failed) / seconds : 0; }
};

/// Sends frames [first, first + count) at `rate_hz` with `send(k)` (false: refused), calling
/// `once_a_second()` between frames about once a second.
template <typename Send, typename Tick>
SendReport send_paced(std::uint64_t first, std::uint64_t count, double rate_hz, Send&& send,
                      Tick&& once_a_second) {
  const auto frames_per_second = std::max<std::uint64_t>(1, static_cast<std::uint64_t>(rate_hz));
  const Pacer pacer(rate_hz);
  const auto start = Clock::now();
  SendReport report;
  for (std::uint64_t k = 0; k < count; ++k) {
    pacer.wait_for(k);
    ++(send(first + k) ? report.sent : report.failed);
    if ((k + 1) % frames_per_second == 0) once_a_second();
  }
  report.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  return report;
}

template <typename Send>
SendReport send_paced(std::uint64_t first, std::uint64_t count, double rate_hz, Send&& send) {
  return send_paced(first, count, rate_hz, send, [] {});
}

/// Sends stamped frames to one UDP destination: `send(k)` stamps frame k now and sends it.
class FrameSender {
 public:
  explicit FrameSender(const transport::Endpoint& to)
      : to_(to), socket_(transport::UdpSocket::for_sending_to(to)) {}
  bool operator()(std::uint64_t k) {
    frames_.stamp_now(k);
    return socket_.send_to(frames_.encode(), to_);
  }

 private:
  transport::Endpoint to_;
  transport::UdpSocket socket_;
  StampedFrames frames_;
};

json to_json(const LatencySummary& summary) {
  return {{"sent", summary.sent},     {"received", summary.received},
          {"lost", summary.lost},     {"duplicates", summary.duplicates},
          {"min_us", summary.min_us}, {"mean_us", summary.mean_us},
          {"p50_us", summary.p50_us}, {"p90_us", summary.p90_us},
          {"p99_us", summary.p99_us}, {"p99.9_us", summary.p999_us},
          {"max_us", summary.max_us}};
}

/// What every latency scenario reports: its settings, the percentiles and, if asked, the CDF.
json latency_result(const BenchOptions& options, const LatencyLog& log, const SendReport& sending) {
  json result = to_json(log.summarize());
  result["rate_hz"] = options.rate_hz;
  result["achieved_rate_hz"] = sending.achieved_rate_hz();
  result["send_failed"] = sending.failed;
  result["duration_s"] = options.duration_s;
  result["warmup_s"] = options.warmup_s;
  result["writer_profile"] = options.writer_profile;
  if (!options.reader_profile.empty()) result["reader_profile"] = options.reader_profile;
  if (!options.cdf_file.empty()) log.write_cdf(options.cdf_file);
  return result;
}

std::string label_of(const Transport& transport, double rate_hz) {
  return std::string(transport.name) + "_" + std::to_string(std::llround(rate_hz)) + "hz";
}

json read_json_file(const std::filesystem::path& file) {
  std::ifstream in(file);
  return in ? json::parse(in, nullptr, /*allow_exceptions=*/false) : json();
}

/// Discovery is not symmetric: the reader seeing the writer does not mean the writer sees the
/// reader, and frames published before it does are lost to that reader. Waits until the gateway's
/// stats file counts `readers` readers of its RobotState writer.
bool wait_for_state_readers(const std::filesystem::path& stats, int readers) {
  const auto deadline = Clock::now() + kStartupTimeout;
  while (Clock::now() < deadline) {
    const json counters = read_json_file(stats);
    if (counters.is_object() && counters.value("state_readers", 0) >= readers) return true;
    std::this_thread::sleep_for(milliseconds(20));
  }
  return false;
}

/// Waits until `log` has a line containing `marker` and returns what follows the marker on it.
std::string wait_for_log_line(const std::filesystem::path& log, std::string_view marker,
                              ChildProcess& process) {
  const auto deadline = Clock::now() + kStartupTimeout;
  while (Clock::now() < deadline) {
    std::ifstream in(log);
    for (std::string line; std::getline(in, line);)
      if (const auto at = line.find(marker); at != std::string::npos) return line.substr(at + marker.size());
    if (!process.running()) throw std::runtime_error("a child exited at start-up; see " + log.string());
    std::this_thread::sleep_for(milliseconds(20));
  }
  throw std::runtime_error("no '" + std::string(marker) + "' in " + log.string());
}

/// A relay under test as a child process -- rsg_gateway or a floor relay -- on a port the kernel
/// picked, logging to the scratch directory.
class GatewayProcess {
 public:
  GatewayProcess(const BenchOptions& options, const Transport& transport, const std::string& topic,
                 const std::string& label)
      : GatewayProcess(
            {(options.tools_dir / "rsg_gateway").string(), "--listen", "127.0.0.1:0", "--domain",
             std::to_string(options.domain), "--topic", topic, "--status-topic", topic + "_status",
             "--profiles", options.profiles_dir.string(), "--participant-profile",
             std::string(transport.participant_profile), "--writer-profile", options.writer_profile,
             "--stats-file", (options.scratch_dir / ("gateway_" + label + "_stats.json")).string()},
            options.scratch_dir / ("gateway_" + label + ".log"),
            options.scratch_dir / ("gateway_" + label + "_stats.json"), options.gateway_args) {}

  /// Any relay that logs "frames on UDP HOST:PORT" once it listens, with `more_args` after
  /// `argv`; `stats`: its stats file, if any.
  GatewayProcess(std::vector<std::string> argv, std::filesystem::path log, std::filesystem::path stats,
                 const std::vector<std::string>& more_args = {})
      : log_(std::move(log)),
        stats_(std::move(stats)),
        process_(concat(std::move(argv), more_args), log_),
        ingress_(wait_for_ingress()) {}

  const transport::Endpoint& ingress() const { return ingress_; }
  /// Waits until the process logs `line` (fails the bench when it exits first or never does).
  void wait_for_log(const std::string& line) { wait_for_log_line(log_, line, process_); }
  pid_t pid() const { return process_.pid(); }
  /// Its stats file (empty for a relay that writes none).
  const std::filesystem::path& stats() const { return stats_; }

  /// Stops it and returns the counters of its final stats file.
  json stop() {
    process_.stop();
    return stats_.empty() ? json() : read_json_file(stats_);
  }

 private:
  static std::vector<std::string> concat(std::vector<std::string> argv,
                                         const std::vector<std::string>& more) {
    argv.insert(argv.end(), more.begin(), more.end());
    return argv;
  }
  // The relay logs where it listens ("... frames on UDP 127.0.0.1:PORT -> ..."): with port 0 that
  // is the only race-free way to learn the port.
  transport::Endpoint wait_for_ingress() {
    const std::string rest = wait_for_log_line(log_, "frames on UDP ", process_);
    return transport::Endpoint::parse(std::string_view(rest).substr(0, rest.find(' ')));
  }

  std::filesystem::path log_;
  std::filesystem::path stats_;
  ChildProcess process_;
  transport::Endpoint ingress_;
};

/// The bench's Cyclone DDS reader (floor/cyclone_reader.cpp) as a child process.
class CycloneReader {
 public:
  CycloneReader(const BenchOptions& options, const std::string& topic, const std::string& label)
      : log_(options.scratch_dir / ("cyclone_reader_" + label + ".log")),
        out_(options.scratch_dir / ("cyclone_reader_" + label + ".txt")),
        process_({(options.bin_dir / "rsg_bench_cyclone_reader").string(), std::to_string(options.domain),
                  topic, std::to_string(options.warmup_frames() + options.measured_frames()), out_.string()},
                 log_) {}

  void wait_for_writer() { wait_for_log_line(log_, "matched", process_); }

  /// Lets it finish (or stops it after `timeout`) and records what it received into `log`.
  void collect(milliseconds timeout, LatencyLog& log) {
    if (!process_.wait_for(timeout)) process_.stop();
    std::ifstream in(out_);
    std::int64_t index = 0, sent = 0, received = 0;
    while (in >> index >> sent >> received)
      log.record(Stamp{static_cast<std::uint64_t>(index), sent}, received);
  }

 private:
  std::filesystem::path log_, out_;
  ChildProcess process_;
};

json usage_json(const ProcessUsage& start, const ProcessUsage& from, const ProcessUsage& to) {
  return {{"t_s", std::chrono::duration<double>(to.at - start.at).count()},
          {"rss_kb", to.rss_kb},
          {"cpu_percent", cpu_percent(from, to)}};
}

void require(bool condition, const std::string& what) {
  if (!condition) throw std::runtime_error(what);
}

}  // namespace

const Transport& transport_named(std::string_view name) {
  for (const Transport& transport : kTransports)
    if (transport.name == name) return transport;
  throw std::invalid_argument("unknown transport '" + std::string(name) +
                              "' (udp, shm, datasharing, udp_default_buffers)");
}

std::uint64_t BenchOptions::warmup_frames() const {
  return static_cast<std::uint64_t>(std::llround(warmup_s * rate_hz));
}
std::uint64_t BenchOptions::measured_frames() const {
  return static_cast<std::uint64_t>(std::llround(duration_s * rate_hz));
}

json run_gateway(const BenchOptions& options, const Transport& transport) {
  const std::string label = label_of(transport, options.rate_hz);
  const std::string topic = options.topic + "_" + label;
  GatewayProcess gateway(options, transport, topic, label);

  dds::Participant participant(options.domain, std::string(transport.participant_profile));
  LatencyLog log(options.warmup_frames(), options.measured_frames());
  LatencyLog notified(options.warmup_frames(), options.measured_frames());
  StateSubscriber subscriber(participant, topic, options.reader_profile_for(transport), log,
                             options.reader_waitset, &notified);
  require(subscriber.wait_for_writer(kStartupTimeout), "the gateway's writer never matched");
  require(wait_for_state_readers(gateway.stats(), 1), "the gateway's writer never matched the reader");

  FrameSender send(gateway.ingress());
  send_paced(0, options.warmup_frames(), options.rate_hz, send);

  // CPU and RSS from the end of warm-up, so start-up and discovery are not counted.
  const ProcessUsage after_warmup = read_usage(gateway.pid());
  const std::uint64_t drops_before = udp_receive_buffer_drops();
  json timeline = json::array();
  ProcessUsage last_usage = after_warmup;
  const auto usage_period = std::chrono::duration<double>(options.usage_period_s);
  const SendReport sending =
      send_paced(options.warmup_frames(), options.measured_frames(), options.rate_hz, send, [&] {
        if (Clock::now() - last_usage.at < usage_period) return;
        const ProcessUsage now = read_usage(gateway.pid());
        timeline.push_back(usage_json(after_warmup, last_usage, now));
        last_usage = now;
      });
  const ProcessUsage at_end = read_usage(gateway.pid());
  timeline.push_back(usage_json(after_warmup, last_usage, at_end));

  subscriber.wait_for_all(kDrainTimeout);
  json result = latency_result(options, log, sending);
  result["transport"] = transport.name;
  result["data_sharing_used"] = maps_data_sharing_segment();
  result["reader_notified"] = to_json(notified.summarize());
  result["host_udp_receive_buffer_drops"] = udp_receive_buffer_drops() - drops_before;
  result["gateway"] = {{"cpu_percent", cpu_percent(after_warmup, at_end)},
                       {"rss_kb_after_warmup", after_warmup.rss_kb},
                       {"rss_kb_end", at_end.rss_kb},
                       {"rss_growth_kb", at_end.rss_kb - after_warmup.rss_kb},
                       {"timeline", std::move(timeline)},
                       {"stats", gateway.stop()}};
  return result;
}

json run_gateway_ros2_standard(const BenchOptions& options, double ros2_standard_hz) {
  BenchOptions with_topics = options;
  with_topics.topic += "_ros2_standard";
  const std::string hz = std::to_string(ros2_standard_hz);
  for (const char* flag : {"--joint-states", "--tf", "--external-wrench"})
    with_topics.gateway_args.insert(with_topics.gateway_args.end(), {flag, hz});
  const Transport& udp = transport_named("udp");
  dds::Participant participant(options.domain, std::string(udp.participant_profile));
  const Ros2StandardReaders readers(participant);
  json result = run_gateway(with_topics, udp);
  result["ros2_standard_hz"] = ros2_standard_hz;
  result["ros2_standard_received"] = readers.counts();
  return result;
}

json run_embedded(const BenchOptions& options) {
  const std::string topic =
      options.topic + "_embedded_" + std::to_string(std::llround(options.rate_hz)) + "hz";
  LatencyLog callback_log(options.warmup_frames(), options.measured_frames());
  LatencyLog reader_log(options.warmup_frames(), options.measured_frames());
  // The clock is read first, as the UDP baseline's receiver and the DDS readers do.
  // --gateway-arg=--KEY=VALUE becomes "KEY: VALUE" of the configuration (e.g. rt-priority).
  std::string more;
  for (const std::string& arg : options.gateway_args)
    if (const auto equals = arg.find('='); arg.starts_with("--") && equals != std::string::npos)
      more += arg.substr(2, equals - 2) + ": " + arg.substr(equals + 1) + "\n";
  const std::filesystem::path stats = options.scratch_dir / (topic + "_stats.json");
  gateway::EmbeddedGateway gateway(more + "listen: 127.0.0.1:0\nstats-file: " + stats.string() +
                                       "\ndomain: " + std::to_string(options.domain) + "\ntopic: " + topic +
                                       "\nstatus-topic: " + topic +
                                       "_status\nprofiles: " + options.profiles_dir.string() +
                                       "\nwriter-profile: " + options.writer_profile + "\n",
                                   [&](const RobotState& sample) {
                                     const std::int64_t received_ns = monotonic_ns();
                                     callback_log.record(read_stamp(sample), received_ns);
                                   });
  // Another participant (intra-process delivery is off in this binary): a remote reader's view.
  const Transport& udp = transport_named("udp");
  dds::Participant participant(options.domain, std::string(udp.participant_profile));
  StateSubscriber subscriber(participant, topic, options.reader_profile_for(udp), reader_log);
  require(subscriber.wait_for_writer(kStartupTimeout), "the embedded gateway's writer never matched");
  require(wait_for_state_readers(stats, 1), "the embedded gateway's writer never matched the reader");

  const transport::Endpoint to = gateway.local_endpoint();
  FrameSender send(to);
  send_paced(0, options.warmup_frames(), options.rate_hz, send);
  const ProcessUsage before = read_usage(::getpid());
  const SendReport sending =
      send_paced(options.warmup_frames(), options.measured_frames(), options.rate_hz, send);
  const ProcessUsage after = read_usage(::getpid());
  subscriber.wait_for_all(kDrainTimeout);
  gateway.stop();
  json result = latency_result(options, callback_log, sending);
  result["dds_reader"] = to_json(reader_log.summarize());
  result["process_cpu_percent"] = cpu_percent(before, after);  // sender, gateway and reader together
  return result;
}

json run_floor(const BenchOptions& options, std::string_view publisher, std::string_view reader) {
  const std::string label = std::string(publisher) + "_to_" + std::string(reader);
  const std::string topic = options.topic + "_" + label;
  const Transport& udp = transport_named("udp");
  std::vector<std::string> argv;
  std::filesystem::path stats;
  if (publisher == "relay_cyclone") {
    argv = {(options.bin_dir / "rsg_bench_relay_cyclone").string(), std::to_string(options.domain), topic};
  } else if (publisher == "relay_fastdds") {
    argv = {(options.bin_dir / "rsg_bench_e2e").string(),
            "--role",
            "relay",
            "--domain",
            std::to_string(options.domain),
            "--topic",
            topic,
            "--profiles",
            options.profiles_dir.string(),
            "--writer-profile",
            "bench_relay_writer"};
  } else {
    stats = options.scratch_dir / ("gateway_" + label + "_stats.json");
    argv = {(options.tools_dir / "rsg_gateway").string(),
            "--listen",
            "127.0.0.1:0",
            "--domain",
            std::to_string(options.domain),
            "--topic",
            topic,
            "--status-topic",
            topic + "_status",
            "--profiles",
            options.profiles_dir.string(),
            "--participant-profile",
            std::string(udp.participant_profile),
            "--writer-profile",
            options.writer_profile,
            "--stats-file",
            stats.string()};
  }
  GatewayProcess relay(argv, options.scratch_dir / (label + ".log"), stats,
                       publisher == "gateway" ? options.gateway_args : std::vector<std::string>{});

  LatencyLog log(options.warmup_frames(), options.measured_frames());
  std::optional<dds::Participant> participant;
  std::optional<StateSubscriber> fastdds_reader;
  std::optional<CycloneReader> cyclone_reader;
  if (reader == "fastdds") {
    participant.emplace(options.domain, std::string(udp.participant_profile));
    fastdds_reader.emplace(*participant, topic, options.reader_profile_for(udp), log, options.reader_waitset);
    require(fastdds_reader->wait_for_writer(kStartupTimeout), "the relay's writer never matched");
  } else {
    cyclone_reader.emplace(options, topic, label);
    cyclone_reader->wait_for_writer();
  }
  if (publisher != "gateway") relay.wait_for_log("relay: writer matched");

  FrameSender send(relay.ingress());
  send_paced(0, options.warmup_frames(), options.rate_hz, send);
  const ProcessUsage before = read_usage(relay.pid());
  const SendReport sending =
      send_paced(options.warmup_frames(), options.measured_frames(), options.rate_hz, send);
  const ProcessUsage after = read_usage(relay.pid());
  if (fastdds_reader)
    fastdds_reader->wait_for_all(kDrainTimeout);
  else
    cyclone_reader->collect(kDrainTimeout, log);
  json result = latency_result(options, log, sending);
  result["publisher"] = publisher;
  result["reader"] = reader;
  result["publisher_cpu_percent"] = cpu_percent(before, after);
  result["publisher_stats"] = relay.stop();
  return result;
}

json run_relay_role(const BenchOptions& options) {
  dds::Participant participant(options.domain, std::string(transport_named("udp").participant_profile));
  fdds::DataWriter* writer = participant.publisher()->create_datawriter_with_profile(
      participant.robot_state_topic(options.topic), options.writer_profile);
  require(writer != nullptr, "cannot create a writer with profile '" + options.writer_profile + "'");
  RobotState sample;
  relay_frames(
      [&](const StampBytes& stamp) {
        std::memcpy(sample.elbow_d().data(), stamp.elbow_d, sizeof(double) * 2);
        std::memcpy(&sample.time(), stamp.time, sizeof sample.time());
        writer->write(&sample);
      },
      [&] {
        fdds::PublicationMatchedStatus status;
        return writer->get_publication_matched_status(status) == dds::kOk && status.current_count > 0;
      });
  return {};
}

json run_max_rate(const BenchOptions& options, const Transport& transport, const std::vector<double>& rates) {
  json steps = json::array();
  double best = 0;
  for (const double rate : rates) {
    BenchOptions step = options;
    step.rate_hz = rate;
    step.warmup_s = std::min(options.warmup_s, 1.0);
    step.cdf_file.clear();
    json run = run_gateway(step, transport);
    const bool kept_rate = run["achieved_rate_hz"].get<double>() >= kMinAchievedRateFraction * rate;
    const bool passed = kept_rate && run["lost"].get<std::uint64_t>() == 0;
    std::cerr << "rsg_bench_e2e: max rate: " << rate << " Hz: " << run["lost"] << " lost, sender at "
              << run["achieved_rate_hz"] << " Hz, gateway CPU " << run["gateway"]["cpu_percent"] << " %\n";
    steps.push_back({{"rate_hz", rate},
                     {"achieved_rate_hz", run["achieved_rate_hz"]},
                     {"sent", run["sent"]},
                     {"received", run["received"]},
                     {"lost", run["lost"]},
                     {"p50_us", run["p50_us"]},
                     {"p99_us", run["p99_us"]},
                     {"gateway_cpu_percent", run["gateway"]["cpu_percent"]},
                     {"host_udp_receive_buffer_drops", run["host_udp_receive_buffer_drops"]},
                     {"gateway_stats", run["gateway"]["stats"]},
                     {"passed", passed},
                     {"sender_kept_rate", kept_rate}});
    if (!passed) break;
    best = rate;
  }
  return {{"max_rate_zero_loss_hz", best},
          {"transport", transport.name},
          {"step_duration_s", options.duration_s},
          {"steps", steps}};
}

json run_udp_oneway(const BenchOptions& options) {
  transport::UdpSocket receiver = transport::UdpSocket::bind(transport::Endpoint::parse("127.0.0.1:0"));
  receiver.set_receive_buffer(kReceiveBufferBytes);
  const transport::Endpoint destination = receiver.local_endpoint();
  LatencyLog log(options.warmup_frames(), options.measured_frames());

  // Receives as the gateway does (poll, then recvfrom into a buffer allocated up front), stamps,
  // and only then decodes to find the frame's own stamp.
  std::jthread receiving([&](std::stop_token stop) {
    std::vector<std::uint8_t> datagram(wire::kMaxFrameBytes + 1);
    while (!stop.stop_requested()) {
      const auto size = receiver.receive(datagram, nullptr, milliseconds(100));
      if (!size) continue;
      const std::int64_t received_ns = monotonic_ns();
      const wire::DecodeResult decoded =
          wire::decode(std::span(datagram).first(std::min(*size, datagram.size())));
      if (!decoded) continue;
      if (const auto stamp = read_stamp(decoded.frame())) log.record(*stamp, received_ns);
    }
  });

  FrameSender send(destination);
  send_paced(0, options.warmup_frames(), options.rate_hz, send);
  const SendReport sending =
      send_paced(options.warmup_frames(), options.measured_frames(), options.rate_hz, send);
  const auto deadline = Clock::now() + kDrainTimeout;
  while (log.arrived() < log.expected() && Clock::now() < deadline)
    std::this_thread::sleep_for(milliseconds(10));
  receiving.request_stop();
  receiving.join();
  return latency_result(options, log, sending);
}

json run_fastdds(const BenchOptions& options, const Transport& transport) {
  const std::string label = label_of(transport, options.rate_hz);
  const std::string topic = options.topic + "_plain_" + label;
  dds::Participant participant(options.domain, std::string(transport.participant_profile));
  LatencyLog log(options.warmup_frames(), options.measured_frames());
  LatencyLog notified(options.warmup_frames(), options.measured_frames());
  StateSubscriber subscriber(participant, topic, options.reader_profile_for(transport), log,
                             options.reader_waitset, &notified);

  const std::filesystem::path writer_log = options.scratch_dir / ("writer_" + label + ".log");
  const std::filesystem::path writer_result = options.scratch_dir / ("writer_" + label + ".json");
  ChildProcess writer({(options.bin_dir / "rsg_bench_e2e").string(),
                       "--role",
                       "writer",
                       "--transport",
                       std::string(transport.name),
                       "--domain",
                       std::to_string(options.domain),
                       "--topic",
                       topic,
                       "--rate",
                       std::to_string(options.rate_hz),
                       "--warmup",
                       std::to_string(options.warmup_s),
                       "--duration",
                       std::to_string(options.duration_s),
                       "--profiles",
                       options.profiles_dir.string(),
                       "--writer-profile",
                       options.writer_profile,
                       "--out",
                       writer_result.string()},
                      writer_log);
  const auto run_time = std::chrono::duration<double>(options.warmup_s + options.duration_s);
  const auto exit_status = writer.wait_for(std::chrono::ceil<milliseconds>(run_time) + 2 * kStartupTimeout);
  require(exit_status == 0, "the writer process failed or hung; see " + writer_log.string());
  const json written = read_json_file(writer_result);
  require(written.is_object(), "the writer process left no result in " + writer_result.string());

  subscriber.wait_for_all(kDrainTimeout);
  const SendReport sending{written["sent"], written["send_failed"], written["seconds"]};
  json result = latency_result(options, log, sending);
  result["transport"] = transport.name;
  result["data_sharing_used"] = maps_data_sharing_segment();
  result["reader_notified"] = to_json(notified.summarize());
  result["writer_cpu_percent"] = written["cpu_percent"];
  return result;
}

json run_writer_role(const BenchOptions& options, const Transport& transport) {
  dds::Participant participant(options.domain, std::string(transport.participant_profile));
  fdds::DataWriter* writer = participant.publisher()->create_datawriter_with_profile(
      participant.robot_state_topic(options.topic), options.writer_profile);
  require(writer != nullptr, "cannot create a writer with profile '" + options.writer_profile + "'");
  const auto deadline = Clock::now() + kStartupTimeout;
  for (fdds::PublicationMatchedStatus matched; matched.current_count == 0;
       writer->get_publication_matched_status(matched)) {
    require(Clock::now() < deadline, "no reader matched");
    std::this_thread::sleep_for(milliseconds(10));
  }

  // The gateway's publish path (Ingress::publish) minus the decode: loan, copy in, write.
  StampedFrames stamped;
  const auto write = [&](std::uint64_t k) {
    stamped.stamp_now(k);
    void* loan = nullptr;
    if (writer->loan_sample(
            loan, fdds::DataWriter::LoanInitializationKind::CONSTRUCTED_LOAN_INITIALIZATION) != rsg::dds::kOk)
      return false;
    stamped.fill(*static_cast<RobotState*>(loan));
    if (rsg::dds::succeeded(writer->write(loan))) return true;
    writer->discard_loan(loan);
    return false;
  };
  send_paced(0, options.warmup_frames(), options.rate_hz, write);
  // This process's CPU over the measured frames: what the gateway's CPU compares with.
  const ProcessUsage before = read_usage(::getpid());
  const SendReport sending =
      send_paced(options.warmup_frames(), options.measured_frames(), options.rate_hz, write);
  const ProcessUsage after = read_usage(::getpid());
  writer->wait_for_acknowledgments(rsg::dds::Duration(5, 0));
  return {{"sent", sending.sent},
          {"send_failed", sending.failed},
          {"seconds", sending.seconds},
          {"cpu_percent", cpu_percent(before, after)}};
}

json run_ddsperf(const BenchOptions& options) {
  // ddsperf prints one line per second per peer:
  //   [pid] 3.000  host:pid size 2137 mean 74.18us min 17.77us 50% 34.31us 90% 48.00us 99% 1439.18us
  //   max 4273.38us cnt 938
  // Percentiles of one second each: they cannot be merged exactly, so the result is their
  // frame-weighted mean (max: the largest), halved for one way. Seconds of warm-up are skipped.
  static const std::regex kInterval(
      R"(\] ([\d.]+) +\S+ size (\d+) mean ([\d.]+)us min ([\d.]+)us 50% ([\d.]+)us 90% ([\d.]+)us )"
      R"(99% ([\d.]+)us max ([\d.]+)us cnt (\d+))");
  static const std::regex kTimeouts(R"(ping timed out \(total (\d+) times\))");
  constexpr int kSampleBytes = 2137;

  const std::string domain = std::to_string(options.domain);
  const int ping_seconds = static_cast<int>(std::ceil(options.warmup_s + options.duration_s)) + 1;
  const int pong_seconds = ping_seconds + 10;  // outlives ping's wait for discovery
  const std::filesystem::path pong_log = options.scratch_dir / "ddsperf_pong.log";
  const std::filesystem::path ping_log = options.scratch_dir / "ddsperf_ping.log";
  ChildProcess pong({options.ddsperf.string(), "-i", domain, "-D", std::to_string(pong_seconds), "pong"},
                    pong_log);
  ChildProcess ping(
      {options.ddsperf.string(), "-i", domain, "-Qminmatch:1", "-Qinitwait:20", "-D",
       std::to_string(ping_seconds), "ping", std::to_string(std::llround(options.rate_hz)) + "Hz", "size",
       std::to_string(kSampleBytes)},
      ping_log);
  const auto exit_status = ping.wait_for(seconds(ping_seconds) + 2 * kStartupTimeout);
  require(exit_status.has_value(), "ddsperf ping hung; see " + ping_log.string());
  pong.stop();

  double weight = 0, p50 = 0, p90 = 0, p99 = 0, mean = 0, max = 0, min = INFINITY;
  std::uint64_t timeouts = 0;
  std::ifstream in(ping_log);
  for (std::string line; std::getline(in, line);) {
    std::smatch match;
    if (std::regex_search(line, match, kTimeouts)) timeouts = std::stoull(match[1]);
    if (!std::regex_search(line, match, kInterval) || std::stod(match[1]) <= options.warmup_s) continue;
    const double count = std::stod(match[9]);
    weight += count;
    mean += count * std::stod(match[3]);
    min = std::min(min, std::stod(match[4]));
    p50 += count * std::stod(match[5]);
    p90 += count * std::stod(match[6]);
    p99 += count * std::stod(match[7]);
    max = std::max(max, std::stod(match[8]));
  }
  require(weight > 0, "no round trips in " + ping_log.string());
  const auto one_way = [&](double weighted_sum) { return weighted_sum / weight / 2; };
  return {{"round_trips", static_cast<std::uint64_t>(weight)},
          {"ping_timeouts", timeouts},
          {"lost", timeouts},
          {"rate_hz", options.rate_hz},
          {"duration_s", options.duration_s},
          {"sample_bytes", kSampleBytes},
          {"min_us", min / 2},
          {"mean_us", one_way(mean)},
          {"p50_us", one_way(p50)},
          {"p90_us", one_way(p90)},
          {"p99_us", one_way(p99)},
          {"max_us", max / 2},
          {"method",
           "half of ddsperf's round trip; per-second percentiles averaged, weighted by round trips "
           "(not exact percentiles of the whole run)"},
          {"ddsperf_exit_status", *exit_status}};
}

}  // namespace rsg::bench
