#include "tools/sim/replay.hpp"

#include <spdlog/spdlog.h>

#include <cmath>
#include <stdexcept>

#include "capture/pcap_file.hpp"
#include "rsg/error.hpp"
#include "rsg/wire/frame.hpp"
#include "tools/sim/udp_stream.hpp"

namespace rsg::tools::sim {
namespace {

using Clock = std::chrono::steady_clock;
using std::chrono::nanoseconds;

// Frames closer together than this are sent back to back after a yield rather than a sleep.
constexpr nanoseconds kSpinWindow = std::chrono::microseconds(200);

std::uint16_t first_frame_port(const std::string& path) {
  capture::PcapReader reader(path);
  while (const auto packet = reader.next())
    if (wire::decode(packet->payload)) return packet->to.port;
  throw InputError("'" + path + "' holds no valid SEND_BUF frame; name the port with --port");
}

}  // namespace

ReplayReport replay(const std::string& path, transport::UdpSocket& socket, const transport::Endpoint& to,
                    const ReplayOptions& options, const std::atomic<bool>& stop) {
  ReplayReport report;
  report.port = options.port ? *options.port : first_frame_port(path);
  spdlog::info("replaying the datagrams to port {} in '{}' to {} at {}x", report.port, path, to.to_string(),
               options.speed);

  Clock::time_point pass_start = Clock::now();
  while (!stop.load(std::memory_order_relaxed)) {
    capture::PcapReader reader(path);
    std::optional<nanoseconds> first;
    nanoseconds last{0};
    std::uint64_t in_pass = 0;
    while (const auto packet = reader.next()) {
      if (packet->to.port != report.port) continue;
      if (!first) first = packet->time;
      last = std::max(last, packet->time - *first);  // a timestamp going back is sent at once
      const auto offset = nanoseconds(std::llround(static_cast<double>(last.count()) / options.speed));
      wait_until(pass_start + offset, kSpinWindow, stop);
      if (stop.load(std::memory_order_relaxed)) break;
      if (socket.send_to(packet->payload, to))
        ++report.sent;
      else
        ++report.send_failures;
      ++in_pass;
    }
    if (in_pass == 0)
      throw InputError("'" + path + "' holds no datagram to port " + std::to_string(report.port));
    if (stop.load(std::memory_order_relaxed)) break;
    ++report.passes;
    if (!options.loop) break;
    // The next pass follows after one mean gap, so a looped capture keeps its rate.
    const auto gap = in_pass > 1 ? last / static_cast<long>(in_pass - 1) : std::chrono::milliseconds(1);
    pass_start += nanoseconds(std::llround(static_cast<double>((last + gap).count()) / options.speed));
  }
  return report;
}

}  // namespace rsg::tools::sim
