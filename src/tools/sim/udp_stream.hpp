// Runs a Simulator on the wall clock and a UDP socket: what `rsg_sim` does once its options are read.
#pragma once

#include <array>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <optional>

#include "capture/pcap_file.hpp"
#include "rsg/transport/udp_socket.hpp"
#include "tools/sim/simulator.hpp"

namespace rsg::tools::sim {

/// Sends to one peer, and reads the selection requests that the peer (or anyone) sends back to the
/// socket's address, which a receiver learns from the source of the datagrams.
class UdpLink final : public DatagramSink {
 public:
  UdpLink(transport::UdpSocket& socket, const transport::Endpoint& peer) : socket_(socket), peer_(peer) {}

  /// Sends, and writes the datagram to the capture when there is one (`rsg_sim --pcap`).
  bool send(std::span<const std::uint8_t> datagram) override;
  /// Also writes every datagram sent into `writer` (null: stop), stamped with the wall clock.
  void capture_to(capture::PcapWriter* writer) { capture_ = writer; }
  /// Hands every datagram waiting on the socket to `sim` as a selection request and logs the outcome.
  void poll_requests(Simulator& sim);

 private:
  transport::UdpSocket& socket_;
  transport::Endpoint peer_;
  capture::PcapWriter* capture_ = nullptr;
  std::optional<capture::UdpEndpoint> capture_from_, capture_to_;  // known after the first send
  std::array<std::uint8_t, wire::kMaxFrameBytes + 1> request_{};   // + 1: an oversized datagram shows as one
};

struct StreamLimits {
  std::optional<std::uint64_t> count;                ///< stop after this many frames
  std::optional<std::chrono::nanoseconds> duration;  ///< stop when the timeline reaches this
};

/// Returns at `deadline` or as soon as `stop` is set; the last `spin_window` before the deadline is
/// spent yielding instead of sleeping, for precise timing at high rates.
void wait_until(std::chrono::steady_clock::time_point deadline, std::chrono::nanoseconds spin_window,
                const std::atomic<bool>& stop);

/// Steps `sim` on an absolute steady_clock timeline (frame n is due at start + n / rate + pauses, so
/// late frames do not delay later ones) until a limit is reached or `stop` is set, polling for
/// selection requests about once a millisecond. Above 2 kHz the last stretch before each deadline
/// is spent yielding instead of sleeping, because a sleeping thread wakes up tens of microseconds
/// late. Ends with `sim.finish`.
void stream(Simulator& sim, UdpLink& link, const StreamLimits& limits, const std::atomic<bool>& stop);

}  // namespace rsg::tools::sim
