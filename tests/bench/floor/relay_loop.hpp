// The leanest UDP -> DDS relay the bench compares rsg_gateway with: receive a datagram (poll,
// then recvfrom, as the gateway does), copy the bench's stamp out of it at a fixed offset, write.
// No CRC, no validation, no counters: the floor a relay written directly on a DDS API can reach.
//
// The offsets of `elbow_d` (the stamp) and `time` are learnt once from the first frame, which is
// decoded for that; the bench sends full frames only, so they never move.
#pragma once

#include <atomic>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <vector>

#include "rsg/transport/udp_socket.hpp"
#include "rsg/wire/frame.hpp"

namespace rsg::bench {

struct StampBytes {
  const std::uint8_t* elbow_d;  ///< 16 bytes: frame index, send time (doubles)
  const std::uint8_t* time;     ///< 8 bytes
};

inline std::atomic<bool> relay_stop{false};

/// Binds 127.0.0.1:0, logs "frames on UDP 127.0.0.1:PORT" (the bench reads the port from it) and
/// calls `write(stamp)` for every datagram until SIGTERM/SIGINT. Logs "relay: writer matched" once
/// `writer_matched()` is true: discovery is not symmetric, so the bench waits for the writer's side
/// too before it sends (a frame written before the writer knows the reader is lost to it).
template <typename Write, typename Matched>
void relay_frames(Write write, Matched writer_matched) {
  std::signal(SIGTERM, [](int) { relay_stop = true; });
  std::signal(SIGINT, [](int) { relay_stop = true; });
  transport::UdpSocket socket = transport::UdpSocket::bind(transport::Endpoint::parse("127.0.0.1:0"));
  socket.set_receive_buffer(4 << 20);
  std::fprintf(stderr, "relay: frames on UDP %s -> DDS\n", socket.local_endpoint().to_string().c_str());
  std::vector<std::uint8_t> datagram(wire::kMaxFrameBytes);
  std::ptrdiff_t elbow_d = -1, time = -1;
  bool matched = false;
  while (!relay_stop) {
    if (!matched && writer_matched()) {
      matched = true;
      std::fprintf(stderr, "relay: writer matched\n");
    }
    const auto size = socket.receive(datagram, nullptr, std::chrono::milliseconds(100));
    if (!size) continue;
    if (elbow_d < 0) {
      const wire::DecodeResult first = wire::decode(std::span(datagram).first(*size));
      if (!first) continue;
      elbow_d = first.frame().field_bytes(wire::Field::elbow_d).data() - datagram.data();
      time = first.frame().field_bytes(wire::Field::time).data() - datagram.data();
    }
    write(StampBytes{datagram.data() + elbow_d, datagram.data() + time});
  }
}

}  // namespace rsg::bench
