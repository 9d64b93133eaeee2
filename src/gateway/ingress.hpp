// Ingress: raw frames from a UDP socket -> RobotState samples.
//
// Runs on the caller's thread (the gateway's main loop); everything it counts is read on that
// same thread, so the hot path takes no lock. Per wake-up it does one poll, then takes the queued
// datagrams in batches (recvmmsg) into buffers allocated at start-up; per datagram one pass that
// checks the CRC and copies the payload into a loaned (or preallocated) sample, and one write. It allocates
// nothing and logs nothing; tests/gateway/ingress_alloc_test.cpp holds it to that (and shows that
// Fast DDS 2.9.1's reliable writer still allocates inside write()).
#pragma once

#include <chrono>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "app/repeated_log.hpp"
#include "gateway/clock.hpp"
#include "gateway/data_sharing.hpp"
#include "gateway/decimator.hpp"
#include "gateway/flight_recorder.hpp"
#include "gateway/latency_histogram.hpp"
#include "gateway/link_monitor.hpp"
#include "gateway/ros2_standard_topics.hpp"
#include "gateway/selection_requester.hpp"
#include "gateway/source_filter.hpp"
#include "rsg/dds/owned.hpp"
#include "rsg/dds/participant.hpp"
#include "rsg/dds/robot_state.hpp"
#include "rsg/transport/udp_socket.hpp"
#include "rsg/wire/frame.hpp"
#include "status/sequence_tracker.hpp"
#include "status/stats.hpp"

namespace rsg::gateway {

class Ingress {
 public:
  struct Options {
    transport::Endpoint listen;
    int receive_buffer = 0;
    SourceFilter sources;
    std::string topic;
    std::string type_name;  ///< "" : rsg::RobotState; else e.g. rsg::dds::kRos2RobotStateType
    std::vector<std::string> partitions;
    std::string writer_profile;
    DataSharing data_sharing = DataSharing::kAsProfiled;  ///< of every writer (entities.hpp)
    Clock::duration nominal_period{};
    std::uint64_t restart_threshold_ms = 0;
    std::optional<wire::Selection> requested_selection;
    std::optional<transport::Endpoint> robot;  ///< where selection requests go; unset: the frames' source
    std::optional<FlightRecorder::Options> flight_recorder;  ///< keep the last seconds of datagrams
    /// Downsampled copies: each topic gets the frames that fall due at its period (same type).
    struct RateTopic {
      std::string topic;
      Decimation rate;
    };
    std::vector<RateTopic> rate_topics;
    /// sensor_msgs/JointState, TF and the external wrench, each at its own rate, written by a
    /// thread of their own from snapshots the ingress thread leaves (ros2_standard_topics.hpp).
    std::optional<Ros2StandardTopics::Options> standard_topics;
    /// Called on the ingress thread with every valid sample just before it is written, so an
    /// in-process consumer (rsg::gateway::EmbeddedGateway) gets it without a socket or a DDS hop.
    std::function<void(const RobotState&)> on_sample;
  };

  /// Binds the socket and creates the writers.
  /// @throws rsg::EnvironmentError when the kernel refuses the socket or Fast DDS a writer.
  Ingress(dds::Participant& participant, Options options);
  ~Ingress();
  Ingress(const Ingress&) = delete;
  Ingress& operator=(const Ingress&) = delete;

  /// Sends the start-up selection request, if one is configured and the robot's address is known.
  void start(Clock::time_point now);

  /// Waits up to `timeout` for datagrams, then handles every one queued, in arrival order (at
  /// most kMaxBatchesPerWake batches, so that a flood cannot keep the caller from its other work).
  void receive(std::chrono::milliseconds timeout);

  static constexpr std::size_t kBatchDatagrams = 32;  ///< per recvmmsg: 32 ms of frames at 1 kHz
  static constexpr std::size_t kMaxBatchesPerWake = 8;

  /// True once for every link change: up on a frame after silence, down after silence, judged by
  /// the frames' arrival times and only while no datagram is queued.
  bool link_changed(Clock::time_point now);
  /// When `link_changed` must be asked next at the latest to notice silence in time.
  Clock::time_point link_deadline() const { return link_.deadline(); }

  /// Frames that passed validation so far.
  std::uint64_t valid_frames() const { return counters_.published + counters_.publish_failed; }

  /// Adds this side's counters to `stats`.
  void fill(status::GatewayStats& stats) const;
  /// Starts a new status period for the per-period figures (ingress_delay_us).
  void end_status_period();

  /// Every valid frame's arrival -> publication since start.
  const LatencyHistogram& delay_histogram() const { return delay_histogram_; }
  /// Every valid frame's age at publication, from the robot's `time` (frames that carry it), beyond
  /// the quickest frame's of the current and the last status period: the robot's clock is not this
  /// host's, so only what a frame took longer than the quickest one recently can be told.
  const LatencyHistogram& age_histogram() const { return age_histogram_; }

  /// Logs what was rejected since the last line (the caller calls it once a second): the first
  /// time at once, then at most one line a minute per kind (app::RepeatedLog), with the counts.
  void log_rejections(Clock::time_point now);

  transport::Endpoint local_endpoint() const { return socket_.local_endpoint(); }

  /// The flight recorder's datagrams, copied for a dump (FlightRecorder::snapshot); nothing when it
  /// is off. Allocates: call it on a request or a link change, not per frame.
  std::optional<FlightRecorder::Snapshot> flight_recorder_snapshot(std::string_view reason);
  bool has_flight_recorder() const { return recorder_.has_value(); }
  /// Datagrams from outside --allow-from the flight recorder did not keep; 0 without one.
  std::uint64_t flight_recorder_not_kept() const { return recorder_ ? recorder_->not_kept() : 0; }

  /// Accepts frames from `sources` from the next datagram on (SIGHUP's reload of allow-from).
  void set_sources(SourceFilter sources);

  /// The standard ROS 2 topics, when any is on.
  const Ros2StandardTopics* standard_topics() const {
    return standard_topics_ ? &*standard_topics_ : nullptr;
  }

 private:
  void handle(const transport::DatagramBatch::Datagram& datagram, Clock::time_point now,
              Clock::time_point arrival);
  void reject(const wire::FrameError& error, const transport::Endpoint& sender);
  void request_selection(const transport::Endpoint& robot);
  void write_rate_topics(const RobotState& sample, std::chrono::nanoseconds t);
  void record_age(std::uint64_t robot_time_ms, Clock::time_point arrival, Clock::time_point published);
  // The consumer, rate topics and standard topics: every output but the full-rate write.
  void deliver(const RobotState& sample, const wire::Selection& selection,
               std::optional<std::uint64_t> robot_time_ms, Clock::time_point now);
  void count_write(bool written);

  // A downsampled writer: writes the frames its decimator takes.
  struct RateWriter {
    dds::OwnedWriter writer;
    Decimator decimator;
  };

  Options options_;
  transport::UdpSocket socket_;
  dds::Participant& participant_;
  // Owners: declared parent first, so that each goes before what created it.
  dds::OwnedPublisher publisher_;
  dds::OwnedWriter writer_;
  bool writer_loans_ = false;
  std::vector<RateWriter> rate_writers_;
  std::optional<Ros2StandardTopics> standard_topics_;  // writes from its thread until destroyed

  // One frame per buffer: anything longer arrives marked truncated and is rejected unread.
  transport::DatagramBatch batch_;
  dds::RobotStateCodec codec_;
  RobotState fallback_sample_;  // when the writer cannot loan: the one preallocated sample
  // The frame SequenceTracker holds (a possible restart), published first if the next confirms it.
  RobotState held_sample_;
  wire::Selection held_selection_;
  std::optional<std::uint64_t> held_time_ms_;

  status::IngressCounters counters_;
  status::SequenceTracker sequence_;
  LinkMonitor link_;
  bool link_came_up_ = false;
  Clock::duration delay_period_max_{};  // arrival -> publication, this status period
  Clock::duration delay_max_{};         // and since start
  LatencyHistogram delay_histogram_;
  LatencyHistogram age_histogram_;
  // The least (arrival - robot time) of this status period and of the last, in ns: the quickest
  // frames' offset between the two clocks, which frame ages are measured from. Two periods, so
  // that the floor follows a drift of the robot's clock and forgets a robot's restart.
  static constexpr std::int64_t kNoFloor = std::numeric_limits<std::int64_t>::max();
  std::int64_t age_floor_ns_ = kNoFloor;
  std::int64_t age_floor_last_ns_ = kNoFloor;
  std::optional<FlightRecorder> recorder_;  // receives into its ring instead of batch_'s storage
  std::optional<SelectionRequester> requester_;
  std::uint8_t request_packet_number_ = 0;

  transport::Endpoint source_;  // sender of the last valid frame
  wire::FrameError last_rejection_;
  transport::Endpoint last_rejected_sender_;
  status::InvalidCounts logged_invalid_{};
  std::uint64_t logged_rejected_source_ = 0;
  std::uint64_t logged_standard_dropped_ = 0;
  transport::Endpoint last_foreign_sender_;
  // Counted once a second, logged once a minute: a misconfigured robot or a flood from outside
  // allow-from would otherwise write a line a second (86,400 a day).
  std::uint64_t counted_rejected_source_ = 0, counted_invalid_ = 0, counted_standard_dropped_ = 0;
  app::RepeatedLog rejected_source_log_, invalid_log_, standard_dropped_log_, request_failed_log_;
};

}  // namespace rsg::gateway
