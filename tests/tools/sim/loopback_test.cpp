// The simulator over a real UDP socket on 127.0.0.1: datagrams arrive whole and decode, and a
// selection request sent back to the datagrams' source address takes effect.
#include <gtest/gtest.h>

#include <atomic>
#include <thread>

#include "rsg/transport/udp_socket.hpp"
#include "tests/support/captured_log.hpp"
#include "tools/sim/simulator.hpp"
#include "tools/sim/udp_stream.hpp"

namespace rsg::tools::sim {
namespace {

using namespace std::chrono_literals;

class Loopback : public ::testing::Test {
 protected:
  transport::UdpSocket receiver_ = transport::UdpSocket::bind(transport::Endpoint::parse("127.0.0.1:0"));
  transport::Endpoint receiver_address_ = receiver_.local_endpoint();
  transport::UdpSocket sender_ = transport::UdpSocket::for_sending_to(receiver_address_);
  UdpLink link_{sender_, receiver_address_};
  std::array<std::uint8_t, wire::kMaxFrameBytes + 1> buffer_{};

  /// The next datagram, or a test failure after a generous timeout (a lost datagram, not a slow one).
  wire::DecodeResult receive(transport::Endpoint* from = nullptr) {
    const auto size = receiver_.receive(buffer_, from, 5s);
    EXPECT_TRUE(size.has_value()) << "no datagram within 5 s";
    return wire::decode(std::span(buffer_).first(size.value_or(0)));
  }
};

TEST_F(Loopback, EveryFrameArrivesAndDecodes) {
  SimConfig config;  // all 44 fields: 2137 bytes, IP-fragmented on a real link
  Simulator sim(config);
  // Lockstep, one datagram in flight: nothing can overflow the receive buffer.
  for (std::uint64_t frame = 0; frame < 300; ++frame) {
    sim.step(link_);
    const wire::DecodeResult decoded = receive();
    ASSERT_TRUE(decoded) << "frame " << frame << ": " << decoded.error().message();
    EXPECT_EQ(decoded.frame().packet_number(), frame % 16);
    EXPECT_EQ(decoded.frame().selection(), wire::Selection::all());
  }
  EXPECT_EQ(sim.report().sent, 300U);
  EXPECT_EQ(sim.report().valid, 300U);
}

TEST_F(Loopback, SelectionRequestToTheSourceAddressTakesEffect) {
  Simulator sim(SimConfig{});
  const test::CapturedLog log;
  sim.step(link_);
  transport::Endpoint robot;
  ASSERT_TRUE(receive(&robot));

  wire::Selection wanted;
  wanted.add(wire::Field::q);
  wanted.add(wire::Field::time);
  std::array<std::uint8_t, wire::kSelectionRequestBytes> request{};
  ASSERT_TRUE(wire::encode_selection_request(0, wanted, request));
  ASSERT_TRUE(receiver_.send_to(request, robot));
  const std::array<std::uint8_t, 5> garbage = {1, 2, 3, 4, 5};
  ASSERT_TRUE(receiver_.send_to(garbage, robot));

  // Both datagrams are queued on the loopback before poll_requests looks, but allow for a slow kernel.
  for (int attempt = 0; attempt < 500 && sim.report().selection_requests + sim.report().invalid_requests < 2;
       ++attempt) {
    link_.poll_requests(sim);
    if (sim.report().selection_requests + sim.report().invalid_requests < 2)
      std::this_thread::sleep_for(10ms);
  }
  EXPECT_EQ(sim.report().selection_requests, 1U);
  EXPECT_EQ(sim.report().invalid_requests, 1U);
  EXPECT_NE(log.text().find("q,time"), std::string::npos) << log.text();

  sim.step(link_);
  const wire::DecodeResult decoded = receive();
  ASSERT_TRUE(decoded);
  EXPECT_EQ(decoded.frame().selection(), wanted);
}

TEST_F(Loopback, StreamStopsAtTheCountAndSendsThemAll) {
  SimConfig config;
  config.rate_hz = 20000;
  config.schedule = Schedule(wire::Selection{});
  config.schedule.add(1, [] {
    wire::Selection joints;
    joints.add(wire::Field::q);
    return joints;
  }());
  Simulator sim(config);
  const std::atomic<bool> stop{false};
  receiver_.set_receive_buffer(1 << 20);
  stream(sim, link_, {.count = 200, .duration = std::nullopt}, stop);
  // Only what the sender did is asserted: whether the kernel kept all 200 is not this test's business.
  EXPECT_EQ(sim.frames(), 200U);
  EXPECT_EQ(sim.report().sent, 200U);
  EXPECT_TRUE(receive());
}

TEST_F(Loopback, StreamReturnsAtOnceWhenStopped) {
  Simulator sim(SimConfig{});
  const std::atomic<bool> stop{true};
  stream(sim, link_, {}, stop);
  EXPECT_EQ(sim.frames(), 0U);
}

}  // namespace
}  // namespace rsg::tools::sim
