// UdpSocket over loopback: round trip, batch receive, oversize detection, address parsing errors.
#include "rsg/transport/udp_socket.hpp"

#include <gtest/gtest.h>

#include <array>
#include <numeric>
#include <stdexcept>
#include <vector>

namespace rsg {
namespace {

using namespace std::chrono_literals;

// The bind-address syntax of rsg/transport/host_port.hpp: HOST "" or "*" is any, port 0 the kernel's pick.
TEST(Endpoint, ParsesV4V6AndRejectsNonsense) {
  EXPECT_EQ(transport::Endpoint::parse("127.0.0.1:7000").to_string(), "127.0.0.1:7000");
  EXPECT_EQ(transport::Endpoint::parse("[::1]:7000").to_string(), "[::1]:7000");
  EXPECT_EQ(transport::Endpoint::parse(":7000").to_string(), "0.0.0.0:7000");
  EXPECT_EQ(transport::Endpoint::parse("*:17000").to_string(), "0.0.0.0:17000");
  EXPECT_EQ(transport::Endpoint::parse(":0").to_string(), "0.0.0.0:0");
  EXPECT_THROW(transport::Endpoint::parse("127.0.0.1"), rsg::InputError);
  EXPECT_THROW(transport::Endpoint::parse("127.0.0.1:notaport"), rsg::InputError);
}

TEST(UdpSocket, RoundTripReportsSourceAndTrueSize) {
  transport::UdpSocket receiver = transport::UdpSocket::bind(transport::Endpoint::parse("127.0.0.1:0"));
  transport::UdpSocket sender = transport::UdpSocket::bind(transport::Endpoint::parse("127.0.0.1:0"));
  const transport::Endpoint to = receiver.local_endpoint();
  ASSERT_NE(to.port(), 0);

  std::array<std::uint8_t, 3000> big{};
  big[0] = 0x30;
  ASSERT_TRUE(sender.send_to(big, to));
  std::array<std::uint8_t, 2200> buffer{};
  transport::Endpoint from;
  const auto size = receiver.receive(buffer, &from, 1000ms);
  ASSERT_TRUE(size.has_value());
  EXPECT_EQ(*size, big.size()) << "an oversized datagram must be reported with its real size";
  EXPECT_EQ(from, sender.local_endpoint());
  EXPECT_FALSE(receiver.receive(buffer, &from, 1ms).has_value());
}

class ReceiveBatch : public ::testing::Test {
 protected:
  // Datagrams sent over loopback are queued by the time send_to returns; waiting for the first
  // one still makes the tests independent of that.
  std::size_t receive(transport::DatagramBatch& batch) {
    if (!receiver_.wait_readable(1000ms)) return 0;
    return receiver_.receive_batch(batch);
  }

  static std::vector<std::uint8_t> datagram(std::size_t size, std::uint8_t first) {
    std::vector<std::uint8_t> bytes(size);
    std::iota(bytes.begin(), bytes.end(), first);
    return bytes;
  }

  transport::UdpSocket receiver_ = transport::UdpSocket::bind(transport::Endpoint::parse("127.0.0.1:0"));
  transport::UdpSocket sender_a_ = transport::UdpSocket::bind(transport::Endpoint::parse("127.0.0.1:0"));
  transport::UdpSocket sender_b_ = transport::UdpSocket::bind(transport::Endpoint::parse("127.0.0.1:0"));
};

TEST_F(ReceiveBatch, TakesSeveralDatagramsInOneCallInOrderWithTheirSenders) {
  const transport::Endpoint to = receiver_.local_endpoint();
  ASSERT_TRUE(sender_a_.send_to(datagram(10, 1), to));
  ASSERT_TRUE(sender_b_.send_to(datagram(20, 2), to));
  ASSERT_TRUE(sender_a_.send_to(datagram(0, 0), to));  // empty datagrams are datagrams too

  transport::DatagramBatch batch(8, 64);
  ASSERT_EQ(receive(batch), 3U);
  ASSERT_EQ(batch.size(), 3U);
  EXPECT_EQ(batch[0].size, 10U);
  EXPECT_EQ(std::vector(batch[0].bytes.begin(), batch[0].bytes.end()), datagram(10, 1));
  EXPECT_EQ(batch[0].from, sender_a_.local_endpoint());
  EXPECT_EQ(batch[1].size, 20U);
  EXPECT_EQ(std::vector(batch[1].bytes.begin(), batch[1].bytes.end()), datagram(20, 2));
  EXPECT_EQ(batch[1].from, sender_b_.local_endpoint());
  EXPECT_EQ(batch[2].size, 0U);
  EXPECT_EQ(batch[2].from, sender_a_.local_endpoint());
  for (std::size_t i = 0; i < batch.size(); ++i) EXPECT_FALSE(batch[i].truncated) << i;
  EXPECT_EQ(receiver_.receive_batch(batch), 0U) << "the queue was drained";
}

TEST_F(ReceiveBatch, StopsAtCapacityAndLeavesTheRestQueued) {
  const transport::Endpoint to = receiver_.local_endpoint();
  for (std::uint8_t i = 0; i < 5; ++i) ASSERT_TRUE(sender_a_.send_to(datagram(4, i), to));

  transport::DatagramBatch batch(2, 16);
  std::vector<std::uint8_t> firsts;
  for (std::size_t expected : {2U, 2U, 1U}) {
    ASSERT_EQ(receive(batch), expected);
    for (std::size_t i = 0; i < batch.size(); ++i) firsts.push_back(batch[i].bytes[0]);
  }
  EXPECT_EQ(firsts, (std::vector<std::uint8_t>{0, 1, 2, 3, 4}));
}

TEST_F(ReceiveBatch, AnOversizeDatagramKeepsItsRealSizeAndIsMarkedTruncated) {
  const transport::Endpoint to = receiver_.local_endpoint();
  ASSERT_TRUE(sender_a_.send_to(datagram(100, 0), to));
  ASSERT_TRUE(sender_a_.send_to(datagram(3000, 7), to));
  ASSERT_TRUE(sender_a_.send_to(datagram(100, 9), to));  // exactly the buffer: not truncated

  transport::DatagramBatch batch(4, 100);
  ASSERT_EQ(receive(batch), 3U);
  EXPECT_FALSE(batch[0].truncated);
  EXPECT_TRUE(batch[1].truncated);
  EXPECT_EQ(batch[1].size, 3000U) << "the real size, not what fit";
  EXPECT_EQ(batch[1].bytes.size(), 100U);
  EXPECT_EQ(batch[1].bytes[0], 7);
  EXPECT_FALSE(batch[2].truncated);
  EXPECT_EQ(batch[2].size, 100U);
  EXPECT_EQ(batch[2].bytes[0], 9) << "the cut datagram did not spill into the next buffer";
}

TEST_F(ReceiveBatch, AnEmptySocketGivesNothingAtOnce) {
  transport::DatagramBatch batch(4, 64);
  const auto start = std::chrono::steady_clock::now();
  EXPECT_EQ(receiver_.receive_batch(batch), 0U);
  EXPECT_TRUE(batch.empty());
  EXPECT_LT(std::chrono::steady_clock::now() - start, 100ms) << "receive_batch must not wait";
  EXPECT_FALSE(receiver_.wait_readable(1ms));
}

TEST_F(ReceiveBatch, ReceivesFromIpv6Senders) {
  std::optional<transport::UdpSocket> bound;
  try {
    bound.emplace(transport::UdpSocket::bind(transport::Endpoint::parse("[::1]:0")));
  } catch (const rsg::EnvironmentError& error) {
    GTEST_SKIP() << "no IPv6 loopback here: " << error.what();
  }
  transport::UdpSocket& receiver = *bound;
  transport::UdpSocket sender = transport::UdpSocket::bind(transport::Endpoint::parse("[::1]:0"));
  ASSERT_TRUE(sender.send_to(datagram(5, 0), receiver.local_endpoint()));
  transport::DatagramBatch batch(2, 8);
  ASSERT_TRUE(receiver.wait_readable(1000ms));
  ASSERT_EQ(receiver.receive_batch(batch), 1U);
  EXPECT_EQ(batch[0].from, sender.local_endpoint());
  EXPECT_EQ(batch[0].from.to_string(), sender.local_endpoint().to_string());
}

TEST(UdpSocket, BindFailureNamesTheAddress) {
  transport::UdpSocket first = transport::UdpSocket::bind(transport::Endpoint::parse("127.0.0.1:0"));
  try {
    transport::UdpSocket::bind(
        transport::Endpoint::parse("192.0.2.1:1"));  // TEST-NET-1: not an address of this host
    FAIL() << "bind to a foreign address succeeded";
  } catch (const rsg::EnvironmentError& error) {
    EXPECT_NE(std::string(error.what()).find("192.0.2.1:1"), std::string::npos) << error.what();
  }
}

TEST(UdpSocket, ASecondBindOfTheSamePortFails) {
  // Two gateways on one port would each get part of the stream; the second must fail loudly.
  transport::UdpSocket first = transport::UdpSocket::bind(transport::Endpoint::parse("127.0.0.1:0"));
  EXPECT_THROW(transport::UdpSocket::bind(first.local_endpoint()), rsg::EnvironmentError);
}

TEST(UdpSocket, MovesOwnershipOfTheDescriptor) {
  transport::UdpSocket a = transport::UdpSocket::bind(transport::Endpoint::parse("127.0.0.1:0"));
  const int fd = a.fd();
  transport::UdpSocket b = std::move(a);
  EXPECT_EQ(b.fd(), fd);
  EXPECT_EQ(a.fd(), -1);  // NOLINT(bugprone-use-after-move): the moved-from state is the contract
}

}  // namespace
}  // namespace rsg
