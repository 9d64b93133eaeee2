#include "tools/sim/udp_stream.hpp"

#include <spdlog/spdlog.h>
#include <sys/socket.h>

#include <algorithm>
#include <cmath>
#include <thread>

namespace rsg::tools::sim {
namespace {

using Clock = std::chrono::steady_clock;
using std::chrono::nanoseconds;

constexpr double kSpinAboveHz = 2000;
constexpr nanoseconds kSpinWindow = std::chrono::microseconds(200);
// Sleeps are cut into slices so that a stop request ends a long pause promptly.
constexpr nanoseconds kLongestSleep = std::chrono::milliseconds(50);
constexpr double kRequestPollsPerSecond = 1000;
// Further behind its schedule than this, the simulator has stalled (a busy host): the schedule goes
// on from now instead of sending the frames due meanwhile in a burst. The robot's time is not moved:
// a frame's `time` set before a send that the host then delays would let the next frame's time
// run ahead of its arrival, which rsg's gateway rightly takes for another stream
// (status/sequence_tracker.hpp). A burst is legal, but one across a --restart-after makes what the
// receiver counts while it confirms the restart a matter of timing, and the tests compare the
// receiver's counters with the simulator's report.
constexpr nanoseconds kMostBehind = std::chrono::milliseconds(2);

std::string describe(const wire::Selection& selection) {
  std::string fields;
  for (const wire::FieldInfo& field : wire::kFields)
    if (selection.contains(field.id())) fields += (fields.empty() ? "" : ",") + std::string(field.name);
  return fields.empty() ? "no field" : fields;
}

}  // namespace

void wait_until(std::chrono::steady_clock::time_point deadline, nanoseconds spin_window,
                const std::atomic<bool>& stop) {
  while (!stop.load(std::memory_order_relaxed)) {
    const nanoseconds remaining = deadline - Clock::now();
    if (remaining <= nanoseconds::zero()) return;
    if (remaining > spin_window)
      std::this_thread::sleep_for(std::min(remaining - spin_window, kLongestSleep));
    else
      std::this_thread::yield();
  }
}

bool UdpLink::send(std::span<const std::uint8_t> datagram) {
  const bool sent = socket_.send_to(datagram, peer_);
  if (capture_ != nullptr) {
    if (!capture_from_) {  // the kernel picks the source port at the first send
      capture_from_ = capture::endpoint_of(socket_.local_endpoint().address());
      capture_to_ = capture::endpoint_of(peer_.address());
      // The socket is unbound, so its address reads 0.0.0.0; the address the kernel sends from is
      // that of a UDP socket connected to the peer (connecting sends nothing).
      transport::UdpSocket probe = transport::UdpSocket::for_sending_to(peer_);
      if (::connect(probe.fd(), peer_.address(), peer_.size()) == 0)
        capture_from_->ip = capture::endpoint_of(probe.local_endpoint().address()).ip;
    }
    const auto now = std::chrono::system_clock::now().time_since_epoch();
    capture_->write({std::chrono::duration_cast<nanoseconds>(now), *capture_from_, *capture_to_, datagram});
  }
  return sent;
}

void UdpLink::poll_requests(Simulator& sim) {
  transport::Endpoint from;
  while (const auto size = socket_.receive(request_, &from, std::chrono::milliseconds(0))) {
    const std::size_t kept = std::min(*size, request_.size());
    const wire::SelectionRequestResult request = sim.handle_request({request_.data(), kept});
    if (request)
      spdlog::info("selection request from {}: now sending {}", from.to_string(),
                   describe(request.selection));
    else
      spdlog::info("ignored an invalid selection request from {} ({}: {})", from.to_string(),
                   wire::to_string(request.error.category()), request.error.message());
  }
}

void stream(Simulator& sim, UdpLink& link, const StreamLimits& limits, const std::atomic<bool>& stop) {
  const double rate = sim.config().rate_hz;
  const nanoseconds spin_window = rate > kSpinAboveHz ? kSpinWindow : nanoseconds::zero();
  const auto poll_every = static_cast<std::uint64_t>(std::max(1.0, rate / kRequestPollsPerSecond));
  const Clock::time_point start = Clock::now();
  nanoseconds paused{0};

  for (std::uint64_t frame = 0; !limits.count || frame < *limits.count; ++frame) {
    const nanoseconds due = nanoseconds(std::llround(static_cast<double>(frame) * 1e9 / rate)) + paused;
    if (limits.duration && due >= *limits.duration) break;
    wait_until(start + due, spin_window, stop);
    if (stop.load(std::memory_order_relaxed)) break;
    if (const nanoseconds behind = Clock::now() - (start + due); behind > kMostBehind) {
      sim.stall();
      paused += behind;
    }
    const std::uint64_t restarts = sim.report().restarts;
    const nanoseconds pause = sim.step(link);
    if (sim.report().restarts != restarts) spdlog::info("robot restarted before frame {}", frame);
    if (pause > nanoseconds::zero())
      spdlog::info("link down for {:g} ms after frame {}",
                   std::chrono::duration<double, std::milli>(pause).count(), frame);
    paused += pause;
    if (frame % poll_every == 0) link.poll_requests(sim);
  }
  sim.finish(link);
}

}  // namespace rsg::tools::sim
