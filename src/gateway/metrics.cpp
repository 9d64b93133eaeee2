#include "gateway/metrics.hpp"

#include <dirent.h>
#include <fmt/format.h>
#include <sys/resource.h>
#include <unistd.h>

#include <ctime>
#include <fstream>
#include <sstream>

namespace rsg::gateway {
namespace {

enum class Type { kCounter, kGauge, kHistogram };

struct Family {
  std::string_view name;
  Type type;
  std::string_view help;
};

// Every family, in the order they are written. Names follow Prometheus' rules: an `rsg_` prefix,
// snake case, base units (seconds, bytes), `_total` on counters and only on counters; the
// process_* families are the names every Prometheus client library uses for the same figures.
constexpr Family kBuildInfo{
    "rsg_build_info", Type::kGauge,
    "Always 1; the labels name rsg's version and the Fast DDS version it was built with"};
constexpr Family kReceived{"rsg_frames_received_total", Type::kCounter,
                           "Datagrams received from allowed sources, valid or not"};
constexpr Family kPublished{"rsg_frames_published_total", Type::kCounter,
                            "Valid frames published as RobotState samples"};
constexpr Family kPublishFailed{"rsg_frames_publish_failed_total", Type::kCounter,
                                "Valid frames DDS refused to write"};
constexpr Family kInvalid{"rsg_frames_invalid_total", Type::kCounter,
                          "Invalid frames, by the wire spec's validation category"};
constexpr Family kRejectedSource{"rsg_frames_rejected_source_total", Type::kCounter,
                                 "Datagrams from sources --allow-from does not accept"};
constexpr Family kLost{"rsg_frames_lost_total", Type::kCounter,
                       "Frames missing from the robot's packet numbers"};
constexpr Family kDuplicated{"rsg_frames_duplicated_total", Type::kCounter, "Frames received twice"};
constexpr Family kReordered{"rsg_frames_reordered_total", Type::kCounter, "Frames received out of order"};
constexpr Family kRestarts{"rsg_robot_restarts_total", Type::kCounter,
                           "Times the robot's time went back by more than --restart-threshold-ms"};
constexpr Family kOutOfSequence{
    "rsg_frames_out_of_sequence_total", Type::kCounter,
    "Valid frames not published: their time went back or jumped ahead of the clock"};
constexpr Family kStandardDropped{"rsg_standard_topics_dropped_total", Type::kCounter,
                                  "Snapshots the ROS 2 standard topics' thread dropped behind"};
constexpr Family kEgressSamples{"rsg_egress_samples_total", Type::kCounter,
                                "Samples taken from the egress topic"};
constexpr Family kEgressSent{"rsg_egress_frames_sent_total", Type::kCounter,
                             "Egress datagrams sent, one per sample and destination"};
constexpr Family kEgressUnencodable{"rsg_egress_unencodable_total", Type::kCounter,
                                    "Egress samples that describe no valid frame"};
constexpr Family kEgressSendFailed{"rsg_egress_send_failed_total", Type::kCounter,
                                   "Egress datagrams the socket refused"};
constexpr Family kEgressRequestLike{
    "rsg_egress_request_like_total", Type::kCounter,
    "Egress samples not sent: the robot would read them as a selection request"};
constexpr Family kEgressRateLimited{"rsg_egress_rate_limited_total", Type::kCounter,
                                    "Egress samples not sent: above --egress-rate"};
constexpr Family kDumps{
    "rsg_flight_recorder_dumps_total", Type::kCounter,
    "Flight-recorder dumps by result: written, failed (the file could not be written), "
    "refused (earlier dumps were still being written) or throttled (asked for sooner than "
    "--pcap-min-interval after the last one)"};
constexpr Family kDumpFilesDeleted{
    "rsg_flight_recorder_files_deleted_total", Type::kCounter,
    "Flight-recorder files deleted, oldest first, to stay within --pcap-max-files "
    "and --pcap-max-mb"};
constexpr Family kDumpNotKept{"rsg_flight_recorder_datagrams_not_kept_total", Type::kCounter,
                              "Datagrams from outside --allow-from the flight recorder left out of its ring "
                              "(--pcap-all-sources keeps them)"};
constexpr Family kReloads{"rsg_config_reloads_total", Type::kCounter,
                          "Configuration reloads on SIGHUP by result: applied, or failed (the running "
                          "configuration stayed)"};
constexpr Family kDdsGuard{
    "rsg_dds_guard_total", Type::kCounter,
    "What the DDS transport guard did: statistics_removed (the statistics submessage "
    "Fast DDS peers put last in every message), statistics_misplaced (one anywhere else: "
    "an attack), send_channel_opened (a reader locator Fast DDS had opened no channel for), "
    "destination_skipped (no channel could be opened: not sent), announcement_refused (a "
    "participant more on probation than one source may have: a discovery flood), lease_shortened "
    "(a new participant's announcement handed on with a 30 s lease until it is proven)"};
constexpr Family kDdsScreen{
    "rsg_dds_screen_dropped_total", Type::kCounter,
    "RTPS messages the screen in front of Fast DDS refused, whole or from one submessage on, by "
    "the check that failed (docs/fastdds-versions.md: each is a published Fast DDS flaw or its kind)"};
constexpr Family kLinkUp{"rsg_link_up", Type::kGauge,
                         "1 while valid frames arrive within the link deadline, else 0"};
constexpr Family kLinkChange{"rsg_link_last_change_timestamp_seconds", Type::kGauge,
                             "Unix time of the last link change (the gateway's start before the first)"};
constexpr Family kRate{"rsg_frame_rate_hertz", Type::kGauge,
                       "Valid frames per second over the last status period (0 while the link is down)"};
constexpr Family kStateReaders{"rsg_state_readers", Type::kGauge, "Readers matched by the RobotState writer"};
constexpr Family kStandardReaders{"rsg_standard_topics_readers", Type::kGauge,
                                  "Readers matched by the ROS 2 standard topics' writers, summed"};
constexpr Family kEgressWriters{"rsg_egress_writers", Type::kGauge, "Writers matched by the egress reader"};
constexpr Family kDelay{"rsg_ingress_delay_seconds", Type::kHistogram,
                        "Time from a valid frame's arrival at the socket to its publication"};
constexpr Family kAge{"rsg_frame_age_seconds", Type::kHistogram,
                      "Time from the robot's time stamp of a frame to its publication, beyond the quickest "
                      "frame's of the last 1-2 s (the robot's clock is not the host's): the robot's and the "
                      "network's jitter and the gateway's delay"};
constexpr Family kDelayMax{"rsg_ingress_delay_max_seconds", Type::kGauge,
                           "Longest time from a frame's arrival to its publication since start"};
constexpr Family kCpu{"process_cpu_seconds_total", Type::kCounter, "User and system CPU time spent, seconds"};
constexpr Family kRss{"process_resident_memory_bytes", Type::kGauge, "Resident memory size, bytes"};
constexpr Family kStart{"process_start_time_seconds", Type::kGauge, "Unix time the process started"};
constexpr Family kFds{"process_open_fds", Type::kGauge, "Open file descriptors"};

constexpr std::array kFamilies = {&kBuildInfo,
                                  &kReceived,
                                  &kPublished,
                                  &kPublishFailed,
                                  &kInvalid,
                                  &kRejectedSource,
                                  &kLost,
                                  &kDuplicated,
                                  &kReordered,
                                  &kRestarts,
                                  &kOutOfSequence,
                                  &kStandardDropped,
                                  &kEgressSamples,
                                  &kEgressSent,
                                  &kEgressUnencodable,
                                  &kEgressSendFailed,
                                  &kEgressRequestLike,
                                  &kEgressRateLimited,
                                  &kDumps,
                                  &kDumpFilesDeleted,
                                  &kDumpNotKept,
                                  &kDdsGuard,
                                  &kDdsScreen,
                                  &kReloads,
                                  &kLinkUp,
                                  &kLinkChange,
                                  &kRate,
                                  &kStateReaders,
                                  &kStandardReaders,
                                  &kEgressWriters,
                                  &kDelay,
                                  &kAge,
                                  &kDelayMax,
                                  &kCpu,
                                  &kRss,
                                  &kStart,
                                  &kFds};

// Backslash and line feed escaped, and the double quote too when `quote` (label values; HELP text
// leaves it).
std::string escape(std::string_view text, bool quote) {
  std::string out;
  for (const char c : text) {
    if (c == '\\')
      out += "\\\\";
    else if (c == '\n')
      out += "\\n";
    else if (c == '"' && quote)
      out += "\\\"";
    else
      out += c;
  }
  return out;
}

class Writer {
 public:
  explicit Writer(const MetricsSnapshot& snapshot) {
    if (!snapshot.gateway.empty()) labels_ += "gateway=\"" + escape_label_value(snapshot.gateway) + '"';
    if (!snapshot.partition.empty())
      labels_ += std::string(labels_.empty() ? "" : ",") + "partition=\"" +
                 escape_label_value(snapshot.partition) + '"';
  }

  void family(const Family& family) {
    out_ += fmt::format("# HELP {} {}\n# TYPE {} {}\n", family.name, escape(family.help, false), family.name,
                        family.type == Type::kCounter ? "counter"
                        : family.type == Type::kGauge ? "gauge"
                                                      : "histogram");
  }

  // One sample with the common labels plus `extra` ("name=\"value\"", already escaped).
  template <class Value>
  void sample(const Family& family, Value value, std::string_view extra = {}, std::string_view suffix = {}) {
    std::string labels = labels_;
    if (!extra.empty()) labels += std::string(labels.empty() ? "" : ",") + std::string(extra);
    out_ += family.name;
    out_ += suffix;
    if (!labels.empty()) out_ += '{' + labels + '}';
    if constexpr (std::is_floating_point_v<Value>)
      out_ += fmt::format(" {}\n", value);
    else
      out_ += fmt::format(" {}\n", static_cast<std::uint64_t>(value));
  }

  template <class Value>
  void one(const Family& f, Value value) {
    family(f);
    sample(f, value);
  }

  // _bucket{le=...} cumulative up to +Inf, _sum, _count.
  void histogram(const Family& f, const LatencyHistogram& histogram) {
    family(f);
    std::uint64_t cumulative = 0;
    for (std::size_t i = 0; i < LatencyHistogram::kBoundsNs.size(); ++i) {
      cumulative += histogram.bucket_count(i);
      sample(f, cumulative,
             fmt::format("le=\"{}\"", static_cast<double>(LatencyHistogram::kBoundsNs[i]) / 1e9), "_bucket");
    }
    sample(f, histogram.count(), "le=\"+Inf\"", "_bucket");
    sample(f, histogram.sum_seconds(), {}, "_sum");
    sample(f, histogram.count(), {}, "_count");
  }

  std::string take() { return std::move(out_); }

 private:
  std::string labels_;
  std::string out_;
};

double seconds_of_us(std::uint64_t us) { return static_cast<double>(us) / 1e6; }

// Unix time of boot: now less the time since boot (CLOCK_BOOTTIME). Not /proc/stat, which a
// systemd unit with ProcSubset=pid hides.
std::optional<double> boot_time_s() {
  timespec since_boot{};
  if (::clock_gettime(CLOCK_BOOTTIME, &since_boot) != 0) return std::nullopt;
  const double unix_now =
      std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
  return unix_now - (static_cast<double>(since_boot.tv_sec) + since_boot.tv_nsec / 1e9);
}

}  // namespace

std::string escape_label_value(std::string_view value) { return escape(value, true); }

std::optional<ProcessFigures> read_process_figures() {
  ProcessFigures figures;
  rusage usage{};
  if (::getrusage(RUSAGE_SELF, &usage) != 0) return std::nullopt;
  const auto seconds = [](const timeval& t) { return static_cast<double>(t.tv_sec) + t.tv_usec / 1e6; };
  figures.cpu_seconds = seconds(usage.ru_utime) + seconds(usage.ru_stime);

  const double page = static_cast<double>(::sysconf(_SC_PAGESIZE));
  const double ticks = static_cast<double>(::sysconf(_SC_CLK_TCK));
  {
    std::ifstream statm("/proc/self/statm");
    double size = 0, resident = 0;
    if (!(statm >> size >> resident)) return std::nullopt;
    figures.resident_bytes = resident * page;
  }
  {
    // Field 22 of /proc/self/stat is the start time in clock ticks after boot; field 2 (the
    // command) may hold spaces, so count from its closing parenthesis.
    std::ifstream stat("/proc/self/stat");
    const std::string text((std::istreambuf_iterator<char>(stat)), std::istreambuf_iterator<char>());
    const auto paren = text.rfind(')');
    if (paren == std::string::npos) return std::nullopt;
    std::istringstream fields(text.substr(paren + 2));
    std::string field;
    for (int index = 3; index <= 22 && fields >> field; ++index) {
      if (index == 22) {
        const auto boot = boot_time_s();
        if (!boot) return std::nullopt;
        figures.start_time_s = *boot + std::stod(field) / ticks;
      }
    }
  }
  if (DIR* dir = ::opendir("/proc/self/fd")) {
    double count = 0;
    while (const dirent* entry = ::readdir(dir))
      if (entry->d_name[0] != '.') ++count;
    ::closedir(dir);
    figures.open_fds = count - 1;  // less the one opendir holds
  }
  return figures;
}

std::string format_metrics(const MetricsSnapshot& snapshot, const std::optional<ProcessFigures>& process) {
  const status::GatewayStats& stats = snapshot.stats;
  Writer out(snapshot);

  out.family(kBuildInfo);
  out.sample(kBuildInfo, 1,
             "version=\"" + escape_label_value(snapshot.version) + "\",fastdds_version=\"" +
                 escape_label_value(snapshot.fastdds_version) + '"');

  out.one(kReceived, stats.ingress.received);
  out.one(kPublished, stats.ingress.published);
  out.one(kPublishFailed, stats.ingress.publish_failed);
  out.family(kInvalid);
  for (std::size_t i = 0; i < stats.ingress.invalid.size(); ++i)
    out.sample(kInvalid, stats.ingress.invalid[i],
               "category=\"" + escape_label_value(wire::to_string(status::category_at(i))) + '"');
  out.one(kRejectedSource, stats.ingress.rejected_source);
  out.one(kLost, stats.sequence.lost);
  out.one(kDuplicated, stats.sequence.duplicated);
  out.one(kReordered, stats.sequence.reordered);
  out.one(kRestarts, stats.sequence.restarts);
  out.one(kOutOfSequence, stats.sequence.out_of_sequence);
  out.one(kStandardDropped, stats.standard_dropped);
  out.one(kEgressSamples, stats.egress.samples);
  out.one(kEgressSent, stats.egress.frames_sent);
  out.one(kEgressUnencodable, stats.egress.unencodable);
  out.one(kEgressSendFailed, stats.egress.send_failed);
  out.one(kEgressRequestLike, stats.egress.request_like);
  out.one(kEgressRateLimited, stats.egress.rate_limited);
  if (const auto& dumps = snapshot.dumps) {
    out.family(kDumps);
    out.sample(kDumps, dumps->written, "result=\"written\"");
    out.sample(kDumps, dumps->failed, "result=\"failed\"");
    out.sample(kDumps, dumps->refused, "result=\"refused\"");
    out.sample(kDumps, dumps->throttled, "result=\"throttled\"");
    out.one(kDumpFilesDeleted, dumps->files_deleted);
    out.one(kDumpNotKept, dumps->not_kept);
  }
  out.family(kDdsGuard);
  out.sample(kDdsGuard, snapshot.dds_guard.statistics_removed, "action=\"statistics_removed\"");
  out.sample(kDdsGuard, snapshot.dds_guard.statistics_misplaced, "action=\"statistics_misplaced\"");
  out.sample(kDdsGuard, snapshot.dds_guard.send_channels_opened, "action=\"send_channel_opened\"");
  out.sample(kDdsGuard, snapshot.dds_guard.destinations_skipped, "action=\"destination_skipped\"");
  out.sample(kDdsGuard, snapshot.dds_guard.announcements_refused, "action=\"announcement_refused\"");
  out.sample(kDdsGuard, snapshot.dds_guard.leases_shortened, "action=\"lease_shortened\"");
  out.family(kDdsScreen);
  for (std::size_t reason = 0; reason < dds::kRtpsScreenReasons; ++reason) {
    const auto name = dds::to_string(static_cast<dds::RtpsScreenReason>(reason));
    out.sample(kDdsScreen, snapshot.dds_guard.screened_out[reason], "reason=\"" + std::string(name) + "\"");
  }
  out.family(kReloads);
  out.sample(kReloads, snapshot.reloads.applied, "result=\"applied\"");
  out.sample(kReloads, snapshot.reloads.failed, "result=\"failed\"");

  out.one(kLinkUp, stats.link_up ? 1 : 0);
  out.one(kLinkChange, snapshot.link_last_change_s);
  out.one(kRate, stats.rate_hz);
  out.one(kStateReaders, stats.state_readers);
  out.one(kStandardReaders, stats.standard_readers);
  out.one(kEgressWriters, stats.egress_writers);
  if (snapshot.has_ingress) {
    out.histogram(kDelay, snapshot.ingress_delay);
    out.histogram(kAge, snapshot.frame_age);
  }
  out.one(kDelayMax, seconds_of_us(stats.ingress_delay_max_us));

  if (process) {
    out.one(kCpu, process->cpu_seconds);
    out.one(kRss, process->resident_bytes);
    out.one(kStart, process->start_time_s);
    out.one(kFds, process->open_fds);
  }
  return out.take();
}

std::vector<std::string> metric_family_names() {
  std::vector<std::string> names;
  for (const Family* family : kFamilies) names.emplace_back(family->name);
  return names;
}

bool is_live(const MetricsSnapshot& snapshot, Clock::time_point now, Clock::duration max_age) {
  return now - snapshot.taken <= max_age;
}

bool is_ready(const MetricsSnapshot& snapshot, Clock::time_point now, Clock::duration max_age) {
  return is_live(snapshot, now, max_age) && (!snapshot.has_ingress || snapshot.stats.link_up);
}

}  // namespace rsg::gateway
