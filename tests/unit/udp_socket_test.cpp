// UdpSocket over loopback: round trip, oversize detection, address parsing errors.
#include "rsg/udp_socket.hpp"

#include <gtest/gtest.h>

#include <array>
#include <stdexcept>

namespace rsg {
namespace {

using namespace std::chrono_literals;

TEST(Endpoint, ParsesV4V6AndRejectsNonsense) {
  EXPECT_EQ(Endpoint::parse("127.0.0.1:7000").to_string(), "127.0.0.1:7000");
  EXPECT_EQ(Endpoint::parse("[::1]:7000").to_string(), "[::1]:7000");
  EXPECT_EQ(Endpoint::parse(":7000").to_string(), "0.0.0.0:7000");
  EXPECT_THROW(Endpoint::parse("127.0.0.1"), std::invalid_argument);
  EXPECT_THROW(Endpoint::parse("127.0.0.1:notaport"), std::invalid_argument);
}

TEST(UdpSocket, RoundTripReportsSourceAndTrueSize) {
  UdpSocket receiver = UdpSocket::bind(Endpoint::parse("127.0.0.1:0"));
  UdpSocket sender = UdpSocket::bind(Endpoint::parse("127.0.0.1:0"));
  const Endpoint to = receiver.local_endpoint();
  ASSERT_NE(to.port(), 0);

  std::array<std::uint8_t, 3000> big{};
  big[0] = 0x30;
  ASSERT_TRUE(sender.send_to(big, to));
  std::array<std::uint8_t, 2200> buffer{};
  Endpoint from;
  const auto size = receiver.receive(buffer, &from, 1000ms);
  ASSERT_TRUE(size.has_value());
  EXPECT_EQ(*size, big.size()) << "an oversized datagram must be reported with its real size";
  EXPECT_EQ(from, sender.local_endpoint());
  EXPECT_FALSE(receiver.receive(buffer, &from, 1ms).has_value());
}

TEST(UdpSocket, BindFailureNamesTheAddress) {
  UdpSocket first = UdpSocket::bind(Endpoint::parse("127.0.0.1:0"));
  try {
    UdpSocket::bind(Endpoint::parse("192.0.2.1:1"));  // TEST-NET-1: not an address of this host
    FAIL() << "bind to a foreign address succeeded";
  } catch (const std::system_error& error) {
    EXPECT_NE(std::string(error.what()).find("192.0.2.1:1"), std::string::npos) << error.what();
  }
}

TEST(UdpSocket, ASecondBindOfTheSamePortFails) {
  // Two gateways on one port would each get part of the stream; the second must fail loudly.
  UdpSocket first = UdpSocket::bind(Endpoint::parse("127.0.0.1:0"));
  EXPECT_THROW(UdpSocket::bind(first.local_endpoint()), std::system_error);
}

TEST(UdpSocket, MovesOwnershipOfTheDescriptor) {
  UdpSocket a = UdpSocket::bind(Endpoint::parse("127.0.0.1:0"));
  const int fd = a.fd();
  UdpSocket b = std::move(a);
  EXPECT_EQ(b.fd(), fd);
  EXPECT_EQ(a.fd(), -1);  // NOLINT(bugprone-use-after-move): the moved-from state is the contract
}

}  // namespace
}  // namespace rsg
