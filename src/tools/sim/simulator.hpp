// The simulated robot's stream, frame by frame, without sockets or clocks: what `rsg_sim` sends and
// what the tests drive directly.
//
//   rsg::tools::sim::Simulator sim(config);
//   while (running) { pause = sim.step(sink); ... }   // sink.send() gets 0..3 datagrams per step
//   sim.finish(sink);
#pragma once

#include <array>
#include <chrono>
#include <cstdint>
#include <optional>
#include <ostream>
#include <span>
#include <string>

#include "rsg/wire/frame.hpp"
#include "rsg/wire/state_values.hpp"
#include "tools/sim/fault_injector.hpp"
#include "tools/sim/panda_model.hpp"
#include "tools/sim/schedule.hpp"
#include "tools/sim/sim_report.hpp"

namespace rsg::tools::sim {

struct SimConfig {
  /// Frames per second of robot time: frame n is stamped n / rate_hz after the robot started.
  double rate_hz = 1000;
  /// Seeds the motion and the faults; the same seed and config give the same datagrams.
  std::uint64_t seed = 1;
  Schedule schedule{wire::Selection::all()};
  FaultConfig faults;
  /// After this many frames (0: never), the link goes silent for `pause`; the robot's clock and
  /// motion keep running, so the next frame's `time` jumps while its packet number follows on.
  std::uint64_t pause_after = 0;
  std::chrono::milliseconds pause{0};
  /// After this many frames (0: never), the robot reboots: `time`, the motion and the packet number
  /// start again from 0. The selection survives.
  std::uint64_t restart_after = 0;
};

/// Where the simulator's datagrams go: a socket in `rsg_sim`, a vector in tests.
class DatagramSink {
 public:
  virtual ~DatagramSink() = default;
  /// False when the datagram could not be sent.
  virtual bool send(std::span<const std::uint8_t> datagram) = 0;
};

class Simulator {
 public:
  explicit Simulator(SimConfig config);

  /// Produces the next frame and hands `sink` what the faults make of it. Returns how long the link
  /// must now stay silent (zero but once with `pause_after`). Does not allocate unless recording.
  std::chrono::nanoseconds step(DatagramSink& sink);
  /// Counts a stall: the host ran the simulator too late to keep its schedule, which then goes on
  /// from there instead of catching up in a burst (udp_stream.cpp). The robot's time stays that of
  /// its frames (frame k at k / rate, plus pauses), so a receiver sees the link silent for a while.
  void stall();
  /// Sends a frame still held back for reordering. Call once at the end of the stream.
  void finish(DatagramSink& sink);

  /// Applies a selection request (docs/protocol.md) received from the gateway: from the next frame on,
  /// the requested selection replaces the schedule. Invalid requests are counted and ignored.
  wire::SelectionRequestResult handle_request(std::span<const std::uint8_t> datagram);

  /// Writes the canonical JSON of every valid datagram sent, one line each, to `out` (null: stop).
  void record_to(std::ostream* out) { record_ = out; }

  const SimReport& report() const { return report_; }
  /// Frames produced so far, dropped ones included.
  std::uint64_t frames() const { return frame_; }
  const SimConfig& config() const { return config_; }
  /// The selection that the next frame gets unless a request arrives first.
  wire::Selection next_selection() const;

 private:
  // A datagram and what a decoder will make of it (kNone: a valid frame).
  struct Datagram {
    std::array<std::uint8_t, kCraftedDatagramBytes> bytes{};
    std::size_t size = 0;
    wire::ErrorCategory category = wire::ErrorCategory::kNone;
    std::span<const std::uint8_t> view() const { return {bytes.data(), size}; }
  };

  void produce_frame();
  void emit(const Datagram& datagram, DatagramSink& sink);
  void record(std::span<const std::uint8_t> frame);

  SimConfig config_;
  PandaModel model_;
  FaultPlan faults_;
  std::optional<wire::Selection> requested_;
  SimReport report_;
  std::optional<std::chrono::steady_clock::time_point> last_sent_;  // for report_.longest_gap_us

  std::uint64_t frame_ = 0;       // frames produced since the start
  std::uint64_t boot_frame_ = 0;  // frame_ at the last (re)start
  std::chrono::nanoseconds paused_since_boot_{0};

  wire::StateValues values_;
  Datagram current_;
  Datagram held_;  // a frame waiting to be sent after the next valid one
  bool holding_ = false;

  std::ostream* record_ = nullptr;
  wire::StateValues recorded_;
  std::string record_line_;
};

}  // namespace rsg::tools::sim
