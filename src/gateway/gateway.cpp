#include "gateway/gateway.hpp"

#include <fmt/ranges.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <filesystem>
#include <utility>

#include "gateway/credentials.hpp"
#include "gateway/errno_text.hpp"
#include "gateway/realtime.hpp"
#include "gateway/version.hpp"
#include "rsg/dds/discovery.hpp"
#include "rsg/dds/fastdds.hpp"
#include "rsg/dds/owned.hpp"
#include "rsg/dds/profiles.hpp"
#include "rsg/dds/ros2.hpp"
#include "rsg/error.hpp"

namespace rsg::gateway {
namespace fdds = eprosima::fastdds::dds;
namespace {

using std::chrono::milliseconds;

constexpr auto kStatusPeriod = std::chrono::seconds(1);
// The longest the loop sleeps: bounds how late it notices a stop request or a due status.
constexpr milliseconds kLongestWait{100};

transport::Endpoint resolve(const std::string& flag, const std::string& host_port) {
  try {
    return transport::Endpoint::parse(host_port);
  } catch (const InputError& error) {
    throw InputError("--" + flag + ": " + error.what());
  }
}

// The `gateway` label: --name, else the partition, else the host's name, so that every gateway has
// one (a dashboard finds the gateways by it) and two hosts' unnamed gateways differ.
std::string gateway_label(const GatewayConfig& config) {
  if (!config.name.empty()) return config.name;
  if (!config.partition.empty()) return config.partition;
  std::array<char, 256> host{};
  if (::gethostname(host.data(), host.size() - 1) == 0 && host[0] != '\0') return host.data();
  return "rsg_gateway";
}

double unix_now_s() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

// A directory the gateway will write into must exist and be writable: said at start-up, naming the
// flag, the file and errno, instead of a warning at every write.
void check_writable_dir(const std::string& flag, const std::filesystem::path& dir, const std::string& file) {
  const std::filesystem::path where = dir.empty() ? std::filesystem::path(".") : dir;
  std::error_code error;
  if (!std::filesystem::exists(where, error))
    throw InputError("--" + flag + ": cannot write '" + file + "': directory '" + where.string() +
                     "': " + errno_text(ENOENT) + " (create it first, e.g. RuntimeDirectory= under systemd)");
  if (!std::filesystem::is_directory(where, error))
    throw InputError("--" + flag + ": cannot write '" + file + "': '" + where.string() +
                     "': " + errno_text(ENOTDIR));
  if (::access(where.c_str(), W_OK | X_OK) != 0)
    throw InputError("--" + flag + ": cannot write '" + file + "': directory '" + where.string() +
                     "': " + errno_text(errno));
}

void check_output_files(const GatewayConfig& config) {
  if (!config.stats_file.empty()) {
    const std::filesystem::path file = config.stats_file;
    std::error_code error;
    if (std::filesystem::is_directory(file, error))
      throw InputError("--stats-file: '" + config.stats_file + "' is a directory: " + errno_text(EISDIR));
    check_writable_dir("stats-file", file.parent_path(), config.stats_file);
  }
  if (config.pcap_ring > 0) check_writable_dir("pcap-dir", config.pcap_dir, config.pcap_dir + "/*.pcap");
}

// The --profiles files or directories, for messages: "a.xml, b/" (or rsg's directory).
std::string profiles_of(const GatewayConfig& config) {
  return config.profiles.empty() ? dds::default_profiles_dir().string()
                                 : fmt::format("{}", fmt::join(config.profiles, ", "));
}

InputError no_profile(const GatewayConfig& config, const std::string& flag, const std::string& kind,
                      const std::string& name) {
  return InputError("--" + flag + ": no " + kind + " profile named '" + name + "' in " + profiles_of(config));
}

// The participant profile's QoS, with systemd's credentials directory in its properties
// (credentials.hpp); looked up before anything exists, and again to create the participant.
fdds::DomainParticipantQos profile_participant_qos(const GatewayConfig& config) {
  fdds::DomainParticipantQos qos;
  if (fdds::DomainParticipantFactory::get_instance()->get_participant_qos_from_profile(
          config.participant_profile, qos) != dds::kOk)
    throw no_profile(config, "participant-profile", "participant", config.participant_profile);
  for (auto& property : qos.properties().properties())
    property.value() = expand_credentials_directory(
        property.value(), std::getenv("CREDENTIALS_DIRECTORY"),
        "participant profile '" + config.participant_profile + "', property " + property.name());
  return qos;
}

void load_and_check_profiles(const GatewayConfig& config) {
  try {
    if (config.profiles.empty()) dds::load_profiles(dds::default_profiles_dir());
    for (const auto& file_or_dir : config.profiles) dds::load_profiles(std::filesystem::path(file_or_dir));
  } catch (const InputError& error) {
    throw InputError(std::string("--profiles: ") + error.what());
  }
  profile_participant_qos(config);
}

// Fast DDS only notices a missing writer or reader profile when an entity is created from it, after
// some of the gateway exists; look first. The lookup needs a publisher or subscriber, and it is done
// through the gateway's own participant: a throwaway participant that is never enabled keeps its
// participant id reserved in Fast DDS 3 for the life of the process, and the gateway's own
// participant would then collide with it.
dds::Participant& check_entity_profiles(dds::Participant& participant, const GatewayConfig& config) {
  const auto has_writer_profile = [&](const std::string& name) {
    const dds::OwnedPublisher publisher = dds::own(participant, participant.publisher());
    fdds::DataWriterQos qos;
    return publisher->get_datawriter_qos_from_profile(name, qos) == dds::kOk;
  };
  const auto has_reader_profile = [&](const std::string& name) {
    const dds::OwnedSubscriber subscriber = dds::own(participant, participant.subscriber());
    fdds::DataReaderQos qos;
    return subscriber->get_datareader_qos_from_profile(name, qos) == dds::kOk;
  };
  if (!has_writer_profile(config.status_profile))
    throw no_profile(config, "status-profile", "data_writer", config.status_profile);
  if (config.has_ingress() && !has_writer_profile(config.writer_profile))
    throw no_profile(config, "writer-profile", "data_writer", config.writer_profile);
  if (config.has_egress() && !has_reader_profile(config.reader_profile))
    throw no_profile(config, "reader-profile", "data_reader", config.reader_profile);
  return participant;
}

// A gateway restarted after a crash must not come back on its predecessor's ports: readers still
// hold the dead participant's state for those locators, and resumed only after 1.6-20 s in
// tests/reliability/test_gateway_restart.py. A participant id taken from the pid gives a restart
// other ports (Fast DDS moves on to free ports if these are taken). A profile that sets <participantID>
// itself is left alone.
fdds::DomainParticipantQos participant_qos(const GatewayConfig& config) {
  fdds::DomainParticipantQos qos = profile_participant_qos(config);
  if (qos.wire_protocol().participant_id < 0)
    qos.wire_protocol().participant_id =
        static_cast<std::int32_t>(::getpid() % transport::kGatewayParticipantIds);
  try {
    dds::apply_discovery({config.discovery_servers, config.peers}, config.domain, qos);
  } catch (const InputError& error) {
    throw InputError(std::string("--discovery-server/--peer: ") + error.what());
  }
  return qos;
}

std::vector<std::string> partitions_of(const GatewayConfig& config) {
  return config.partition.empty() ? std::vector<std::string>{} : std::vector<std::string>{config.partition};
}

// The DDS topic of a configured topic name: itself, or its ROS 2 name in the namespace.
std::string dds_topic(const GatewayConfig& config, const std::string& name) {
  return config.ros2 ? dds::ros2_topic_name(config.ros2_namespace, name) : name;
}

std::string state_type_name(const GatewayConfig& config) {
  return config.ros2 ? std::string(dds::kRos2RobotStateType) : std::string();
}

std::string status_topic_of(const GatewayConfig& config) {
  return config.ros2 ? dds::ros2_topic_name(config.ros2_namespace, "gateway_status") : config.status_topic;
}

DataSharing data_sharing_of(const GatewayConfig& config) {
  return config.data_sharing == "off" ? DataSharing::kOff : DataSharing::kAsProfiled;
}

// joint_states and external_wrench in the namespace; tf absolute (/tf), where tf2 and RViz listen.
std::optional<Ros2StandardTopics::Options> standard_topics_of(const GatewayConfig& config) {
  Ros2StandardTopics::Options options;
  const auto output = [&](const std::string& rate, const std::string& name) {
    return rate.empty()
               ? std::nullopt
               : std::optional(Ros2StandardTopics::Output{*parse_decimation(rate), dds_topic(config, name)});
  };
  options.joint_states = output(config.joint_states, "joint_states");
  options.tf = output(config.tf, config.ros2 ? "/tf" : "tf");
  options.external_wrench = output(config.external_wrench, "external_wrench");
  if (!options.any()) return std::nullopt;
  options.joint_names = config.joint_names;
  options.base_frame = config.base_frame;
  options.ee_frame = config.ee_frame;
  options.wrench_frame = config.wrench_frame;
  options.data_sharing = data_sharing_of(config);
  return options;
}

}  // namespace

GatewaySetup prepare(const GatewayConfig& config) {
  if (auto problem = check_config(config)) throw InputError(*problem);

  check_output_files(config);

  GatewaySetup setup{config, std::nullopt, std::nullopt, std::nullopt};
  if (config.has_ingress()) {
    Ingress::Options ingress;
    ingress.listen = resolve("listen", config.listen);
    ingress.receive_buffer = config.receive_buffer;
    for (const auto& network : config.allow_from) {
      const wire::Parsed<Network> parsed = parse_network(network);
      if (!parsed) throw InputError("--allow-from: " + parsed.error());
      ingress.sources.allow(*parsed);
    }
    ingress.topic = dds_topic(config, config.topic);
    ingress.type_name = state_type_name(config);
    for (const auto& value : config.rate_topics) {
      const RateTopic rate = *parse_rate_topic(value);
      ingress.rate_topics.push_back({dds_topic(config, rate.name), rate.rate});
    }
    ingress.standard_topics = standard_topics_of(config);
    ingress.partitions = partitions_of(config);
    ingress.writer_profile = config.writer_profile;
    ingress.data_sharing = data_sharing_of(config);
    ingress.nominal_period = std::chrono::duration_cast<Clock::duration>(
        std::chrono::duration<double>(1.0 / config.expected_rate));
    ingress.restart_threshold_ms = static_cast<std::uint64_t>(config.restart_threshold_ms);
    if (config.requests_selection()) ingress.requested_selection = requested_selection(config);
    if (!config.robot.empty()) ingress.robot = resolve("robot", config.robot);
    if (config.pcap_ring > 0) {
      ingress.flight_recorder =
          FlightRecorder::Options{std::chrono::duration<double>(config.pcap_ring), config.expected_rate,
                                  config.pcap_dir, config.pcap_all_sources};
    }
    setup.ingress = std::move(ingress);
  }
  if (config.has_egress()) {
    Egress::Options egress;
    egress.topic = dds_topic(config, config.egress_topic.empty() ? "robot_state_cmd" : config.egress_topic);
    egress.type_name = state_type_name(config);
    egress.partitions = partitions_of(config);
    egress.reader_profile = config.reader_profile;
    egress.data_sharing = data_sharing_of(config);
    for (const auto& destination : config.send_to)
      egress.destinations.push_back(resolve("send-to", destination));
    egress.max_rate_hz = config.egress_rate > 0 ? config.egress_rate : config.expected_rate;
    setup.egress = std::move(egress);
  }
  if (!config.metrics.empty()) setup.metrics = resolve("metrics", config.metrics);
  load_and_check_profiles(config);
  return setup;
}

Gateway::Gateway(const GatewaySetup& setup)
    : config_(setup.config),
      participant_(config_.domain, participant_qos(config_)),
      status_(check_entity_profiles(participant_, config_), status_topic_of(config_), partitions_of(config_),
              config_.status_profile, data_sharing_of(config_),
              config_.ros2 ? std::string(dds::kRos2GatewayStatusType) : std::string()),
      stats_file_(config_.stats_file) {
  if (setup.ingress) {
    ingress_.emplace(participant_, *setup.ingress);
    if (ingress_->has_flight_recorder())
      dump_writer_.emplace(DumpWriter::Options{config_.pcap_dir,
                                               std::chrono::duration<double>(config_.pcap_min_interval),
                                               static_cast<std::size_t>(config_.pcap_max_files),
                                               static_cast<std::uintmax_t>(config_.pcap_max_mb) << 20});
    spdlog::info("ingress: frames on UDP {} -> topic '{}' (domain {})",
                 ingress_->local_endpoint().to_string(), setup.ingress->topic, config_.domain);
    if (const auto& standard = setup.ingress->standard_topics) {
      for (const auto& [output, rate] :
           {std::pair{&standard->joint_states, &config_.joint_states}, std::pair{&standard->tf, &config_.tf},
            std::pair{&standard->external_wrench, &config_.external_wrench}})
        if (*output) spdlog::info("ROS 2 standard topic '{}' at {}", (*output)->topic, *rate);
    }
  }
  if (setup.egress) {
    egress_.emplace(participant_, *setup.egress);
    spdlog::info("egress: topic '{}' -> UDP {}", setup.egress->topic, fmt::join(config_.send_to, ", "));
  }
  link_last_change_s_ = unix_now_s();
  gateway_label_ = gateway_label(config_);
  if (setup.metrics) {
    MetricsServer::Options options{*setup.metrics};
    options.max_connections = static_cast<std::size_t>(config_.metrics_max_connections);
    options.max_connections_per_client = static_cast<std::size_t>(config_.metrics_max_connections_per_client);
    options.header_timeout = std::chrono::milliseconds(config_.metrics_header_timeout_ms);
    options.idle_timeout = std::chrono::milliseconds(config_.metrics_idle_timeout_ms);
    metrics_.emplace(options, metrics_snapshot(snapshot(), Clock::now()));
    spdlog::info("metrics: /metrics, /livez and /readyz on {} (TCP port {})", config_.metrics,
                 metrics_->port());
  }
}

void Gateway::run(const std::atomic<bool>& stop, std::atomic<bool>* dump, LoopObserver* observer,
                  PendingReload* reload) {
  const auto start = Clock::now();
  if (ingress_) {
    ingress_->start(start);
    no_link_.emplace(ingress_->local_endpoint().to_string(), start);
  }
  rate_.update(0, start);
  const status::GatewayStats first = snapshot();
  status_.publish(first);
  stats_file_.write_now(first);  // before READY: a stats file exists once the gateway is up
  if (metrics_) metrics_->publish(metrics_snapshot(first, start));
  if (observer != nullptr) observer->started(first, ingress_.has_value());
  auto next_status = start + kStatusPeriod;
  summary_.emplace(start);

  while (!stop.load(std::memory_order_relaxed)) {
    // Wake for the next frame, the next status, or the moment silence means the link is down.
    const auto wake = ingress_ ? std::min(next_status, ingress_->link_deadline()) : next_status;
    const auto wait =
        std::clamp(std::chrono::ceil<milliseconds>(wake - Clock::now()), milliseconds(0), kLongestWait);
    if (ingress_)
      ingress_->receive(wait);
    else
      std::this_thread::sleep_for(wait);

    const auto now = Clock::now();
    if (ingress_ && ingress_->link_changed(now)) on_link_change();
    if (dump != nullptr && dump->exchange(false)) dump_flight_recorder("signal");
    if (reload != nullptr) take_reload(*reload);
    if (now >= next_status) {
      const status::GatewayStats stats = on_status_period(now);
      if (observer != nullptr) observer->status(stats, ingress_.has_value());
      next_status = std::max(next_status + kStatusPeriod, now);  // after a stall, do not catch up
    }
    if (observer != nullptr) observer->turned(now);  // the watchdog: only while this loop turns
  }

  if (observer != nullptr) observer->stopping();
  const status::GatewayStats final_stats = snapshot();
  status_.publish(final_stats);
  stats_file_.write_now(final_stats);
  spdlog::info("stopping: {}", summary_line(final_stats));
}

void Gateway::on_link_change() {
  const status::GatewayStats stats = snapshot();
  spdlog::info("link {} ({})", stats.link_up ? "up" : "down", stats.source);
  status_.publish(stats);  // now, not at the next period: readers act on link changes
  link_last_change_s_ = unix_now_s();
  if (metrics_) metrics_->publish(metrics_snapshot(stats, Clock::now()));
  if (!stats.link_up) dump_flight_recorder("link_down");
}

void Gateway::dump_flight_recorder(std::string_view reason) {
  if (!ingress_ || !ingress_->has_flight_recorder()) {
    if (reason == "signal") spdlog::warn("SIGUSR1: no flight recorder to dump (start with --pcap-ring)");
    return;
  }
  // The copy here, the file on the dump writer's thread: this is the ingress thread.
  const auto now = Clock::now();
  switch (dump_writer_->post(std::string(reason), now,
                             [&] { return *ingress_->flight_recorder_snapshot(reason); })) {
    case DumpWriter::Posted::kQueued:
      break;
    case DumpWriter::Posted::kThrottled:  // counted; a flapping link or a signal flood logs once a minute
      if (dump_throttled_log_.allow(now))
        spdlog::warn(
            "flight recorder ({}): not dumped, less than --pcap-min-interval {} s after the last dump "
            "({} such requests since start)",
            reason, config_.pcap_min_interval, dump_writer_->throttled());
      break;
    case DumpWriter::Posted::kRefused:
      if (dump_refused_log_.allow(now))
        spdlog::error(
            "flight recorder ({}): not dumped, {} earlier dumps are still being written ({} refused "
            "since start)",
            reason, DumpWriter::kMaxPending, dump_writer_->refused());
      break;
  }
}

void PendingReload::offer(Read read) {
  const std::lock_guard lock(mutex_);
  read_ = std::move(read);
  offered_.store(true, std::memory_order_release);
}

std::optional<PendingReload::Read> PendingReload::take() {
  if (!offered_.exchange(false, std::memory_order_acquire)) return std::nullopt;
  const std::lock_guard lock(mutex_);
  return std::exchange(read_, std::nullopt);
}

void Gateway::take_reload(PendingReload& pending) {
  std::optional<PendingReload::Read> read = pending.take();
  if (!read) return;
  try {
    if (const auto* why = std::get_if<std::string>(&*read)) throw InputError(*why);
    reload(std::get<GatewayConfig>(*read));
    ++reloads_.applied;
  } catch (const InputError& error) {
    ++reloads_.failed;
    spdlog::error("SIGHUP: configuration not reloaded, the running one stays: {}", error.what());
  }
  if (metrics_) metrics_->publish(metrics_snapshot(snapshot(), Clock::now()));
}

void Gateway::reload(const GatewayConfig& fresh) {
  if (auto problem = check_config(fresh)) throw InputError(*problem);
  SourceFilter sources;
  for (const auto& network : fresh.allow_from) {
    const wire::Parsed<Network> parsed = parse_network(network);
    if (!parsed) throw InputError("--allow-from: " + parsed.error());
    sources.allow(*parsed);
  }
  // Every key that differs: the two a running gateway can take, and the rest, named.
  std::vector<std::string> applied, need_restart;
  for (const ConfigKey& key : config_keys()) {
    const bool differs =
        std::visit([&](auto member) { return config_.*member != fresh.*member; }, key.member);
    if (!differs) continue;
    if (key.name == "allow-from")
      applied.push_back(fmt::format("allow-from [{}] (was [{}])", fmt::join(fresh.allow_from, ", "),
                                    fmt::join(config_.allow_from, ", ")));
    else if (key.name == "log-level")
      applied.push_back(fmt::format("log-level {} (was {})", fresh.log_level, config_.log_level));
    else
      need_restart.push_back("--" + std::string(key.name));
  }
  if (ingress_) ingress_->set_sources(std::move(sources));
  config_.allow_from = fresh.allow_from;
  spdlog::info("SIGHUP: configuration reloaded: {}", applied.empty()
                                                         ? std::string("allow-from and log-level unchanged")
                                                         : fmt::format("{}", fmt::join(applied, ", ")));
  if (!need_restart.empty())
    spdlog::warn("SIGHUP: not applied until a restart: {} (a reload applies allow-from and log-level)",
                 fmt::join(need_restart, ", "));
  // Last, so that lowering the level does not hide the lines above.
  config_.log_level = fresh.log_level;
  spdlog::set_level(spdlog::level::from_str(log_level_name(fresh)));  // checked: any case
}

status::GatewayStats Gateway::on_status_period(Clock::time_point now) {
  if (ingress_) {
    rate_hz_ = rate_.update(ingress_->valid_frames(), now);
    ingress_->log_rejections();
  }
  const status::GatewayStats stats = snapshot();
  if (ingress_) ingress_->end_status_period();
  status_.publish(stats);
  stats_file_.post(stats);  // written by its own thread: never a disk wait here
  if (metrics_) metrics_->publish(metrics_snapshot(stats, now));
  if (no_link_)
    if (const auto warning = no_link_->due(stats, now)) spdlog::warn("{}", *warning);
  if (summary_->may_log(now))
    if (std::string line = summary_line(stats); summary_->due(line, now)) spdlog::info("{}", line);
  return stats;
}

status::GatewayStats Gateway::snapshot() const {
  status::GatewayStats stats;
  if (ingress_) ingress_->fill(stats);
  if (egress_) {
    stats.egress = egress_->counters();
    stats.egress_writers = egress_->matched_writers();
  }
  stats.rate_hz = stats.link_up ? rate_hz_ : 0.0;
  return stats;
}

MetricsSnapshot Gateway::metrics_snapshot(const status::GatewayStats& stats, Clock::time_point now) const {
  MetricsSnapshot metrics;
  metrics.stats = stats;
  metrics.has_ingress = ingress_.has_value();
  if (dump_writer_)
    metrics.dumps =
        DumpCounts{dump_writer_->written(),   dump_writer_->failed(),  dump_writer_->refused(),
                   dump_writer_->throttled(), dump_writer_->deleted(), ingress_->flight_recorder_not_kept()};
  metrics.reloads = reloads_;
  const dds::RtpsGuardCounts& guard = participant_.rtps_guard();
  metrics.dds_guard = DdsGuardCounts{guard.statistics_removed.load(std::memory_order_relaxed),
                                     guard.statistics_misplaced.load(std::memory_order_relaxed),
                                     guard.send_channels_opened.load(std::memory_order_relaxed),
                                     guard.destinations_skipped.load(std::memory_order_relaxed),
                                     guard.announcements_refused.load(std::memory_order_relaxed),
                                     guard.leases_shortened.load(std::memory_order_relaxed)};
  for (std::size_t reason = 0; reason < dds::kRtpsScreenReasons; ++reason)
    metrics.dds_guard.screened_out[reason] = guard.screened_out[reason].load(std::memory_order_relaxed);
  metrics.link_last_change_s = link_last_change_s_;
  if (ingress_) {
    metrics.ingress_delay = ingress_->delay_histogram();
    metrics.frame_age = ingress_->age_histogram();
  }
  metrics.gateway = gateway_label_;
  metrics.partition = config_.partition;
  metrics.version = rsg_version();
  metrics.fastdds_version = fastdds_version();
  metrics.taken = now;
  return metrics;
}

void enter_realtime_mode(const GatewayConfig& config) {
  const RealtimeRequest request{config.rt_priority, config.cpu};
  if (!request.any()) return;
  const RealtimeOutcome outcome = enter_realtime(request);
  if (!outcome.problems.empty()) {
    spdlog::warn("real-time mode degraded, running without what was refused: {}", outcome.problems);
    return;
  }
  std::string done;
  if (outcome.fifo) done += "SCHED_FIFO priority " + std::to_string(request.priority) + ", memory locked";
  if (outcome.pinned)
    done += (done.empty() ? "" : ", ") + std::string("on CPU ") + std::to_string(request.cpu);
  spdlog::info("real-time mode: ingress thread {}", done);
}

}  // namespace rsg::gateway
