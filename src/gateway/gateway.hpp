// The gateway process: one participant and, as configured, ingress, egress and status.
//
// Start-up is split so that nothing half-starts: `prepare()` resolves addresses, loads the XML
// profiles and checks that every named profile exists -- all before any socket or DDS entity
// exists -- and only then does `Gateway` create them.
#pragma once

#include <atomic>
#include <fastdds/dds/domain/qos/DomainParticipantQos.hpp>
#include <mutex>
#include <optional>
#include <string>
#include <variant>

#include "app/repeated_log.hpp"
#include "gateway/config.hpp"
#include "gateway/dump_writer.hpp"
#include "gateway/egress.hpp"
#include "gateway/ingress.hpp"
#include "gateway/link_monitor.hpp"
#include "gateway/log_throttle.hpp"
#include "gateway/loop_observer.hpp"
#include "gateway/metrics_server.hpp"
#include "gateway/no_link_warning.hpp"
#include "gateway/stats_file.hpp"
#include "gateway/status_publisher.hpp"
#include "rsg/dds/writer_directory.hpp"

namespace rsg::gateway {

/// A checked configuration with its addresses resolved.
struct GatewaySetup {
  GatewayConfig config;
  std::optional<Ingress::Options> ingress;
  std::optional<Egress::Options> egress;
  std::optional<transport::Endpoint> metrics;  ///< where /metrics is served
};

/// What prepare() prepares for: a start, or `--check-config`, which accepts the directories the
/// systemd unit creates at its start missing (they exist only while it runs).
enum class PrepareFor { kStart, kCheck };

/// Resolves and checks everything that can be checked without creating entities.
/// @throws rsg::InputError with a message naming the flag, file or profile at fault.
GatewaySetup prepare(const GatewayConfig& config, PrepareFor purpose = PrepareFor::kStart);

/// The participant profile's QoS, with ${CREDENTIALS_DIRECTORY} expanded in its properties.
/// @throws rsg::InputError when the profile is not loaded or a property needs a credential that
/// systemd did not hand over.
eprosima::fastdds::dds::DomainParticipantQos profile_participant_qos(const GatewayConfig& config);

/// A configuration re-read for SIGHUP on the signal's thread, handed to the loop, which never
/// reads files: the configuration, or why it could not be read.
class PendingReload {
 public:
  using Read = std::variant<GatewayConfig, std::string>;
  /// Any thread; a newer offer replaces one not taken yet.
  void offer(Read read);
  /// The loop's thread: what was offered since the last call, if anything.
  std::optional<Read> take();

 private:
  std::atomic<bool> offered_{false};  // checked every turn without the lock
  std::mutex mutex_;
  std::optional<Read> read_;  // guarded by mutex_
};

class Gateway {
 public:
  /// Binds, creates the DDS entities and starts egress.
  /// @throws rsg::EnvironmentError when the kernel or DDS refuses (a port that is taken, an entity),
  /// rsg::InputError for a view or profile that turns out unusable.
  explicit Gateway(const GatewaySetup& setup);

  /// Writes the first status and stats file, then receives, publishes and reports until `stop` is
  /// set, then writes the final status. Whenever `dump` (when given) is set, it clears it and
  /// hands a flight-recorder dump to the dump writer's thread. `observer` (when given) hears of
  /// the start, every turn of the loop and every status period, on this thread.
  /// Whenever `reload` (when given) holds a configuration, applies it (`reload`).
  void run(const std::atomic<bool>& stop, std::atomic<bool>* dump = nullptr, LoopObserver* observer = nullptr,
           PendingReload* reload = nullptr);

  /// What became of a reload.
  enum class Reloaded { kApplied, kRefused };

  /// Applies what of `fresh` can change while running -- allow-from and log-level -- and logs it,
  /// and names every other key that differs as needing a restart. A configuration that widens
  /// access (widened_access()) is refused unless it sets reload-widens-access: nothing changes
  /// then, and the refusal is logged at warning.
  /// @throws rsg::InputError when `fresh` does not pass check_config; nothing changes then.
  Reloaded reload(const GatewayConfig& fresh);

  /// Where ingress receives frames; nothing when there is no ingress.
  std::optional<transport::Endpoint> ingress_endpoint() const {
    return ingress_ ? std::optional(ingress_->local_endpoint()) : std::nullopt;
  }

 private:
  void on_link_change();
  void check_other_writers();
  void dump_flight_recorder(std::string_view reason);
  void take_reload(PendingReload& reload);
  void log_held_events(Clock::time_point now);                   // the counts app::RepeatedLog held back
  status::GatewayStats on_status_period(Clock::time_point now);  // returns the stats it reported
  status::GatewayStats snapshot() const;
  MetricsSnapshot metrics_snapshot(const status::GatewayStats& stats, Clock::time_point now) const;

  GatewayConfig config_;
  dds::WriterDirectory writers_;  // before the participant, whose discovery it hears
  dds::Participant participant_;  // outlives every entity below
  StatusPublisher status_;
  std::optional<Ingress> ingress_;
  std::optional<Egress> egress_;
  RateMeter rate_;
  double rate_hz_ = 0;
  std::optional<SummaryPacer> summary_;    // from run()
  std::optional<NoLinkWarning> no_link_;   // with ingress
  StatsFile stats_file_;                   // --stats-file, written by a thread of its own
  std::optional<DumpWriter> dump_writer_;  // with a flight recorder: writes its dumps
  // Per-event lines an outsider can repeat (a flapping link, a signal storm): app::RepeatedLog.
  app::RepeatedLog dump_throttled_log_, dump_refused_log_, no_recorder_log_;
  app::RepeatedLog link_up_log_, link_down_log_;
  app::RepeatedLog reload_applied_log_, reload_refused_log_, reload_failed_log_;
  ReloadCounts reloads_;
  std::string own_participant_;            // participant_'s GUID prefix, dds::participant_key
  std::string state_topic_;                // ingress's DDS topic; "" without ingress
  std::uint32_t other_state_writers_ = 0;  // of state_topic_ in the partition, by other programs
  double link_last_change_s_ = 0;          // Unix time, for the metrics
  std::string gateway_label_;              // the metrics' `gateway` label
  std::optional<MetricsServer> metrics_;   // last: serves snapshots of everything above
};

/// Why a reload from `running` to `fresh` would widen who can reach the gateway, or nothing: an
/// allow-from that disappears or grows to everyone (0.0.0.0/0, ::/0), a participant profile or
/// profile list that changes (DDS Security lives there), data-sharing from off to auto.
std::optional<std::string> widened_access(const GatewayConfig& running, const GatewayConfig& fresh);

/// Puts the calling thread (the one that will call `Gateway::run`) in the configured real-time
/// mode, logging what was refused. Call it once the Gateway exists: Fast DDS has created its
/// threads by then, and they must not inherit the ingress thread's priority and CPU.
void enter_realtime_mode(const GatewayConfig& config);

}  // namespace rsg::gateway
