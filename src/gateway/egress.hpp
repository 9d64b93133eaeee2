// Egress: RobotState samples -> raw frames sent to one or more UDP destinations.
//
// Runs its own thread, woken by a WaitSet when samples arrive, so a slow DDS side never stalls
// ingress. Samples are taken as loans (zero-copy with data-sharing) and encoded into one buffer
// allocated at start-up. A frame that went raw -> DDS -> raw comes out byte-identical, because
// the sample keeps the packet number and the selection and the encoder rewrites exactly that.
//
// What reaches the robot is bounded, since any participant of the domain may write the egress
// topic (docs/security.md): at most `max_rate_hz` samples a second (a token bucket that lets
// kBurst of a second through at once, so a writer's jitter costs nothing), and never a frame the
// robot would read as something else. A frame with an empty data section (L = 0) is byte for byte
// a selection request (docs/protocol.md), so such a sample is refused, not sent.
#pragma once

#include <algorithm>
#include <array>
#include <atomic>
#include <fastdds/dds/core/condition/GuardCondition.hpp>
#include <fastdds/dds/core/condition/WaitSet.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <string>
#include <thread>
#include <vector>

#include "app/repeated_log.hpp"
#include "gateway/clock.hpp"
#include "gateway/data_sharing.hpp"
#include "rsg/dds/owned.hpp"
#include "rsg/dds/participant.hpp"
#include "rsg/dds/robot_state.hpp"
#include "rsg/transport/udp_socket.hpp"
#include "rsg/wire/frame.hpp"
#include "status/stats.hpp"

namespace rsg::gateway {

/// At most `rate` events a second on average, and `burst` at once: a token bucket.
class RateBudget {
 public:
  RateBudget(double rate, double burst) : rate_(rate), burst_(std::max(burst, 1.0)), tokens_(burst_) {}

  /// True (and one token is spent) when an event may happen at `now`.
  bool take(Clock::time_point now) {
    const double seconds = std::chrono::duration<double>(now - last_).count();
    last_ = now;
    if (seconds > 0) tokens_ = std::min(burst_, tokens_ + seconds * rate_);
    if (tokens_ < 1) return false;
    tokens_ -= 1;
    return true;
  }

 private:
  double rate_;
  double burst_;
  double tokens_;
  Clock::time_point last_{};
};

class Egress {
 public:
  struct Options {
    std::string topic;
    std::string type_name;  ///< "" : rsg::RobotState; else e.g. rsg::dds::kRos2RobotStateType
    std::vector<std::string> partitions;
    std::string reader_profile;
    DataSharing data_sharing = DataSharing::kAsProfiled;  ///< of the reader (entities.hpp)
    std::vector<transport::Endpoint> destinations;
    /// Samples sent per second at most (each to every destination); > 0.
    double max_rate_hz = 1000;
  };

  /// The share of a second of `max_rate_hz` that may go out at once.
  static constexpr double kBurstSeconds = 0.1;

  /// Creates the reader and the sockets, then starts the thread.
  /// @throws rsg::EnvironmentError when DDS or the kernel refuses the reader or a socket.
  Egress(dds::Participant& participant, const Options& options);
  /// Stops the thread, then deletes the reader.
  ~Egress();
  Egress(const Egress&) = delete;
  Egress& operator=(const Egress&) = delete;

  /// The counters so far; safe from any thread.
  status::EgressCounters counters() const;
  /// Writers of the egress topic currently matched.
  std::uint32_t matched_writers() const;

 private:
  struct Destination {
    transport::Endpoint endpoint;
    transport::UdpSocket socket;
  };

  void run();
  void forward_available();
  void forward(const RobotState& sample);
  void log_unencodable();
  void log_refused();

  dds::Participant& participant_;
  dds::OwnedSubscriber subscriber_;
  dds::OwnedReader reader_;
  std::vector<Destination> destinations_;
  std::array<std::uint8_t, wire::kMaxFrameBytes> frame_{};
  dds::RobotStateCodec codec_;  // used by the forwarding thread only

  eprosima::fastdds::dds::WaitSet waitset_;
  eprosima::fastdds::dds::GuardCondition stop_;

  // Written by the egress thread only, read by the status loop.
  std::atomic<std::uint64_t> samples_{0};
  std::atomic<std::uint64_t> frames_sent_{0};
  std::atomic<std::uint64_t> unencodable_{0};
  std::atomic<std::uint64_t> send_failed_{0};
  std::atomic<std::uint64_t> request_like_{0};
  std::atomic<std::uint64_t> rate_limited_{0};
  RateBudget budget_;  // egress thread only
  double max_rate_hz_;
  // Egress thread only: the rate-limited log of samples that are no valid frame.
  wire::FrameError last_encode_error_;
  std::uint64_t counted_unencodable_ = 0, counted_request_like_ = 0, counted_rate_limited_ = 0;
  app::RepeatedLog unencodable_log_, request_like_log_, rate_limited_log_;

  std::jthread thread_;  // last: starts once everything it uses exists; named rsg-egress
};

}  // namespace rsg::gateway
