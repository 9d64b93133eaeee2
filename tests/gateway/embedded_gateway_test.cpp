// rsg::gateway::EmbeddedGateway: the callback gets exactly the samples a reader in another participant
// receives over the network (the same frames, byte for byte, in the same order), never a rejected
// frame, and nothing after stop(); an unusable configuration throws before anything starts.
#include "rsg/gateway/embedded_gateway.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/qos/DataReaderQos.hpp>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <mutex>
#include <random>
#include <set>
#include <thread>

#include "dds/internal/fastdds_compat.hpp"
#include "rsg/dds/participant.hpp"
#include "rsg/dds/robot_state.hpp"
#include "tests/support/random_state.hpp"
#include "tests/support/test_domain.hpp"

namespace rsg {
namespace fdds = eprosima::fastdds::dds;
namespace {

using namespace std::chrono_literals;
using Bytes = std::vector<std::uint8_t>;

constexpr std::size_t kFrames = 300;
constexpr std::size_t kCorruptEvery = 10;

std::string config(int domain, const std::string& topic, const std::string& stats_file = {}) {
  return "listen: 127.0.0.1:0\nlog-level: warn\ndomain: " + std::to_string(domain) + "\ntopic: " + topic +
         "\nstatus-topic: " + topic + "_status\nprofiles: " RSG_PROFILES_DIR "\n" +
         (stats_file.empty() ? std::string() : "stats-file: " + stats_file + "\n");
}

// Whether the gateway's stats file (rewritten once a second) counts `readers` matched state readers.
bool stats_count_readers(const std::string& stats_file, int readers) {
  std::ifstream in(stats_file);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  return text.find("\"state_readers\":" + std::to_string(readers)) != std::string::npos;
}

Bytes frame_of(const RobotState& sample) {
  Bytes frame(wire::kMaxFrameBytes);
  const wire::EncodeResult encoded = dds::to_frame(sample, frame);
  EXPECT_TRUE(encoded);
  frame.resize(encoded.size);
  return frame;
}

class EmbeddedGatewayTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    // The reader must get its samples over the network, as a reader in another process would.
    rsg::dds::internal::disable_intraprocess_delivery();
  }
  const int domain_ = rsg::test::test_domain();
};

TEST_F(EmbeddedGatewayTest, CallbackSeesExactlyWhatARemoteReaderReceives) {
  std::mutex mutex;
  std::vector<Bytes> from_callback;
  const std::string stats_file =
      ::testing::TempDir() + "embedded_same_" + std::to_string(::getpid()) + ".json";
  gateway::EmbeddedGateway gateway(config(domain_, "embedded_same", stats_file),
                                   [&](const RobotState& sample) {
                                     const std::lock_guard lock(mutex);
                                     from_callback.push_back(frame_of(sample));
                                   });

  dds::Participant participant(domain_, "rsg_participant");
  fdds::DataReaderQos qos = fdds::DATAREADER_QOS_DEFAULT;
  qos.reliability().kind = fdds::RELIABLE_RELIABILITY_QOS;
  qos.history().kind = fdds::KEEP_ALL_HISTORY_QOS;
  qos.data_sharing().off();  // the network, not shared memory
  fdds::DataReader* reader =
      participant.subscriber()->create_datareader(participant.robot_state_topic("embedded_same"), qos);
  ASSERT_NE(reader, nullptr);
  fdds::SubscriptionMatchedStatus matched;
  for (int i = 0; i < 1000 && matched.current_count == 0; ++i) {
    std::this_thread::sleep_for(10ms);
    reader->get_subscription_matched_status(matched);
  }
  ASSERT_EQ(matched.current_count, 1) << "the embedded gateway's writer never matched";
  // Discovery is not symmetric: the writer must have matched the reader too, or what it writes
  // before then reaches nobody.
  bool writer_matched = false;
  for (int i = 0; i < 1000 && !writer_matched; ++i) {
    writer_matched = stats_count_readers(stats_file, 1);
    if (!writer_matched) std::this_thread::sleep_for(10ms);
  }
  ASSERT_TRUE(writer_matched) << "the embedded gateway's writer never counted the reader";

  std::mt19937_64 rng(3);
  std::vector<Bytes> sent;
  const transport::Endpoint to = gateway.local_endpoint();
  transport::UdpSocket robot = transport::UdpSocket::for_sending_to(to);
  for (std::size_t i = 0; i < kFrames; ++i) {
    wire::StateValues values = test::random_state(rng);
    values.packet_number = static_cast<std::uint8_t>(i % wire::kPacketNumberModulo);
    // The robot's clock goes forward a millisecond a frame: a frame whose time does not continue
    // the stream is not published (docs/operating.md).
    if (values.selection.contains(wire::Field::time)) values.set_integer(wire::Field::time, 1'000'000 + i);
    Bytes frame(wire::kMaxFrameBytes);
    frame.resize(
        encode(values.packet_number, values.selection, values.storage(), wire::StateValues::layout(), frame)
            .size);
    if (i % kCorruptEvery == kCorruptEvery - 1)
      frame.back() ^= 0xFF;  // rejected: neither the callback nor DDS may see it
    else
      sent.push_back(frame);
    ASSERT_TRUE(robot.send_to(frame, to));
    // A frame a millisecond, as the robot's clock above: no burst beyond the socket buffer, and no
    // frame from a future the arrival clock has not reached.
    std::this_thread::sleep_for(1ms);
  }

  std::vector<Bytes> from_reader;
  RobotState sample;
  fdds::SampleInfo info;
  for (int i = 0; i < 1000 && from_reader.size() < sent.size(); ++i) {
    while (reader->take_next_sample(&sample, &info) == rsg::dds::kOk)
      if (info.valid_data) from_reader.push_back(frame_of(sample));
    if (from_reader.size() < sent.size()) std::this_thread::sleep_for(10ms);
  }
  participant.subscriber()->delete_datareader(reader);
  gateway.stop();
  std::remove(stats_file.c_str());

  const std::lock_guard lock(mutex);
  ASSERT_EQ(from_callback.size(), sent.size());
  ASSERT_EQ(from_reader.size(), sent.size());
  for (std::size_t i = 0; i < sent.size(); ++i) {
    EXPECT_EQ(from_callback[i], sent[i]) << "callback sample " << i << " is not the frame sent";
    EXPECT_EQ(from_reader[i], from_callback[i]) << "sample " << i << ": the reader got something else";
  }
}

TEST_F(EmbeddedGatewayTest, NoCallbackAfterStop) {
  std::atomic<int> calls{0};
  gateway::EmbeddedGateway gateway(config(domain_, "embedded_stop"), [&](const RobotState&) { ++calls; });
  const transport::Endpoint to = gateway.local_endpoint();
  gateway.stop();
  gateway.stop();  // idempotent
  EXPECT_THROW(gateway.local_endpoint(), std::logic_error);
  wire::StateValues values;
  values.selection = wire::Selection::all();
  Bytes frame(wire::kMaxFrameBytes);
  frame.resize(encode(0, values.selection, values.storage(), wire::StateValues::layout(), frame).size);
  transport::UdpSocket robot = transport::UdpSocket::for_sending_to(to);
  robot.send_to(frame, to);  // the port is closed: may be refused
  std::this_thread::sleep_for(50ms);
  EXPECT_EQ(calls.load(), 0);
}

// The names of this process's threads, as top -H and tests/integration/thread_freeze.py read them.
std::set<std::string> thread_names() {
  std::set<std::string> names;
  for (const auto& task : std::filesystem::directory_iterator("/proc/self/task")) {
    std::ifstream comm(task.path() / "comm");
    std::string name;
    if (std::getline(comm, name)) names.insert(name);
  }
  return names;
}

TEST_F(EmbeddedGatewayTest, EveryThreadOfTheGatewayNamesItselfByItsRole) {
  const std::string stats_file = ::testing::TempDir() + "rsg_embedded_threads_" + std::to_string(::getpid());
  gateway::EmbeddedGateway gateway(config(domain_, "embedded_threads", stats_file) +
                                       "egress-topic: embedded_threads_cmd\nsend-to: [127.0.0.1:9]\n"
                                       "metrics: 127.0.0.1:0\njoint-states: 10\n",
                                   [](const RobotState&) {});
  const std::set<std::string> expected{"rsg-ingress", "rsg-stats", "rsg-egress", "rsg-metrics",
                                       "rsg-ros2-topics"};
  std::set<std::string> missing = expected;
  // Each thread names itself first thing; give them a moment to have started.
  for (int attempt = 0; attempt < 100 && !missing.empty(); ++attempt) {
    const std::set<std::string> names = thread_names();
    std::erase_if(missing, [&](const std::string& name) { return names.contains(name); });
    if (!missing.empty()) std::this_thread::sleep_for(20ms);
  }
  EXPECT_TRUE(missing.empty()) << "threads not found by name: " << ::testing::PrintToString(missing);
  gateway.stop();
  std::remove(stats_file.c_str());
}

TEST_F(EmbeddedGatewayTest, UnusableConfigurationThrowsNamingTheProblem) {
  const auto message_of = [](const std::string& yaml) {
    try {
      gateway::EmbeddedGateway gateway(yaml, [](const RobotState&) {});
    } catch (const rsg::InputError& error) {
      return std::string(error.what());
    }
    return std::string("no exception");
  };
  EXPECT_NE(message_of("domain: 3\n").find("`listen` is required"), std::string::npos);
  EXPECT_NE(message_of("listen: 127.0.0.1:0\nexpected-rate: -1\n").find("expected-rate"), std::string::npos);
  EXPECT_NE(message_of("listen: 127.0.0.1:0\nno-such-key: 1\n").find("line 2"), std::string::npos);
  EXPECT_NE(
      message_of("listen: 127.0.0.1:0\nprofiles: " RSG_PROFILES_DIR "\nwriter-profile: nope\n").find("nope"),
      std::string::npos);
}

}  // namespace
}  // namespace rsg
