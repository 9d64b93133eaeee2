// `rsg_sim --replay`: sends the SEND_BUF datagrams of a capture (pcap or pcapng, e.g. from tcpdump
// next to a real robot) to a gateway again, with their original spacing.
#pragma once

#include <atomic>
#include <cstdint>
#include <optional>
#include <string>

#include "rsg/transport/udp_socket.hpp"

namespace rsg::tools::sim {

struct ReplayOptions {
  double speed = 1.0;  ///< 2: twice as fast; gaps between datagrams are divided by it
  bool loop = false;   ///< start over at the end until stopped
  /// Replay the datagrams sent to this UDP port. Default: the destination port of the capture's
  /// first valid SEND_BUF frame.
  std::optional<std::uint16_t> port;
};

struct ReplayReport {
  std::uint16_t port = 0;  ///< the destination port replayed
  std::uint64_t sent = 0;  ///< datagrams sent, over all passes
  std::uint64_t send_failures = 0;
  std::uint64_t passes = 0;  ///< complete passes through the file
};

/// Sends the payload of every UDP datagram to the chosen port in `path` to `to`, in file order, the
/// first one at once and each other one as long after it as the capture says (divided by `speed`).
/// Invalid frames are sent as they are: a replay reproduces what the robot sent.
/// @throws rsg::InputError for an unreadable file or one without a SEND_BUF frame to find the port by.
ReplayReport replay(const std::string& path, transport::UdpSocket& socket, const transport::Endpoint& to,
                    const ReplayOptions& options, const std::atomic<bool>& stop);

}  // namespace rsg::tools::sim
