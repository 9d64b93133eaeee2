// The ingress hot path (frame in -> decode -> loaned sample -> write) allocates nothing in
// steady state. Counts operator new calls made by this thread over 10,000 frames after warm-up
// (tests/support/allocation_counter.hpp).
#include <RobotStatePubSubTypes.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/qos/DataWriterQos.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/qos/DataReaderQos.hpp>
#include <memory>
#include <random>
#include <thread>

#include "dds/internal/fastdds_compat.hpp"
#include "dds/internal/rtps_screen.hpp"
#include "dds/internal/spdp_admission.hpp"
#include "rsg/dds/participant.hpp"
#include "rsg/dds/profiles.hpp"
#include "rsg/dds/robot_state.hpp"
#include "rsg/wire/frame.hpp"
#include "tests/support/allocation_counter.hpp"
#include "tests/support/random_state.hpp"
#include "tests/support/test_domain.hpp"

namespace rsg {
namespace fdds = eprosima::fastdds::dds;
namespace {

constexpr int kWarmUp = 1'000;
constexpr int kMeasured = 10'000;

std::vector<std::vector<std::uint8_t>> make_frames(int count) {
  std::mt19937_64 rng(5);
  std::vector<std::vector<std::uint8_t>> frames;
  for (int i = 0; i < count; ++i) {
    wire::StateValues values = test::random_state(rng);
    values.packet_number = static_cast<std::uint8_t>(i % 16);
    std::vector<std::uint8_t> frame(wire::kMaxFrameBytes);
    frame.resize(wire::encode(values.packet_number, values.selection, values.storage(),
                              wire::StateValues::layout(), frame)
                     .size);
    frames.push_back(std::move(frame));
  }
  return frames;
}

TEST(HotPath, DecodeIntoASampleAllocatesNothing) {
  const auto frames = make_frames(64);
  RobotState sample;
  dds::RobotStateCodec codec;
  std::size_t decoded = 0;
  test::AllocationCounter allocations;
  allocations.resume();
  for (int i = 0; i < kMeasured; ++i)
    decoded += static_cast<bool>(codec.decode(frames[static_cast<std::size_t>(i) % frames.size()], sample));
  allocations.pause();
  EXPECT_EQ(decoded, static_cast<std::size_t>(kMeasured));
  EXPECT_EQ(allocations.total(), 0U) << allocations.first_by_rsg();
}

/// An RTPS message as a reader of the gateway receives it: INFO_TS, a 2.1 kB DATA, a HEARTBEAT.
std::vector<std::uint8_t> state_message() {
  std::vector<std::uint8_t> m{'R', 'T', 'P', 'S', 2, 3, 0x01, 0x0f, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12};
  const auto sub = [&m](std::uint8_t id, std::uint8_t flags, std::vector<std::uint8_t> body) {
    m.insert(m.end(), {id, flags, static_cast<std::uint8_t>(body.size()),
                       static_cast<std::uint8_t>(body.size() >> 8)});
    m.insert(m.end(), body.begin(), body.end());
  };
  sub(0x09, 0x01, std::vector<std::uint8_t>(8, 1));
  std::vector<std::uint8_t> data{0, 0, 16, 0, 0, 0, 1, 7, 0, 0, 1, 2, 0, 0, 0, 0, 1, 0, 0, 0};
  data.resize(data.size() + 2140, 0x5a);
  sub(0x15, 0x05, data);
  sub(0x07, 0x01, {0, 0, 1, 7, 0, 0, 1, 2, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0});
  return m;
}

// Every received datagram goes through the screen and the discovery admission (rtps_guard.cpp):
// neither may allocate.
TEST(HotPath, ScreeningAReceivedMessageAllocatesNothing) {
  const auto message = state_message();
  const auto size = static_cast<std::uint32_t>(message.size());
  auto admission = std::make_unique<dds::internal::SpdpAdmission>();
  const dds::internal::AnnouncementSource source{};
  std::uint32_t forwarded = 0;
  test::AllocationCounter allocations;
  allocations.resume();
  for (int i = 0; i < kMeasured; ++i) {
    const auto screen = dds::internal::screen_rtps_datagram(message.data(), size);
    forwarded += screen.forward_bytes == size;
    admission->admit(message.data(), screen.forward_bytes, source,
                     dds::internal::SpdpAdmission::Clock::now());
  }
  allocations.pause();
  EXPECT_EQ(forwarded, static_cast<std::uint32_t>(kMeasured));
  EXPECT_EQ(allocations.total(), 0U) << allocations.first_by_rsg();
}

void expect_no_allocations_while_publishing(const std::string& profile, bool reader_data_sharing) {
  // A reader in a second participant and no intra-process shortcut, so the measured writes really
  // reach another participant through a transport or data-sharing.
  rsg::dds::internal::disable_intraprocess_delivery();
  const int domain = rsg::test::test_domain();
  dds::load_profiles(std::filesystem::path(RSG_TEST_DATA_DIR) / "hot_path_profiles.xml");
  dds::Participant publishing(domain, profile);
  dds::Participant subscribing(domain, profile);

  fdds::DataWriterQos qos = fdds::DATAWRITER_QOS_DEFAULT;
  qos.history().kind = fdds::KEEP_LAST_HISTORY_QOS;
  // Deep enough that the writer does not lap a data-sharing reader: Fast DDS 2.9.1's
  // DataSharingListener crashed now and then with a history of 1 (about 1 run in 3 here).
  qos.history().depth = 100;
  qos.reliability().kind = fdds::BEST_EFFORT_RELIABILITY_QOS;
  qos.endpoint().history_memory_policy = rsg::dds::rtps::PREALLOCATED_MEMORY_MODE;
  fdds::DataWriter* writer =
      publishing.publisher()->create_datawriter(publishing.robot_state_topic("hot_path"), qos);
  ASSERT_NE(writer, nullptr);

  fdds::DataReaderQos reader_qos = fdds::DATAREADER_QOS_DEFAULT;
  reader_qos.reliability().kind = fdds::BEST_EFFORT_RELIABILITY_QOS;
  if (reader_data_sharing) {
    reader_qos.data_sharing().automatic();
  } else {
    reader_qos.data_sharing().off();
  }
  fdds::DataReader* reader =
      subscribing.subscriber()->create_datareader(subscribing.robot_state_topic("hot_path"), reader_qos);
  ASSERT_NE(reader, nullptr);
  // Both sides: a best-effort reader drops what arrives before it has matched the writer itself.
  // Waiting for the writer's side only, the UDP case got nothing in 2 runs of 20 on Fast DDS 3.1.2
  // (0 of 40 with this wait).
  fdds::PublicationMatchedStatus matched;
  fdds::SubscriptionMatchedStatus reader_matched;
  for (int i = 0; i < 500 && (matched.current_count == 0 || reader_matched.current_count == 0); ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    writer->get_publication_matched_status(matched);
    reader->get_subscription_matched_status(reader_matched);
  }
  ASSERT_EQ(matched.current_count, 1) << "the reader never matched";
  ASSERT_EQ(reader_matched.current_count, 1) << "the reader never matched the writer";

  const auto frames = make_frames(64);
  dds::RobotStateCodec codec;
  auto publish = [&](const std::vector<std::uint8_t>& frame) {
    void* loan = nullptr;
    if (writer->loan_sample(loan) != rsg::dds::kOk) return false;
    if (!codec.decode(frame, *static_cast<RobotState*>(loan))) {
      writer->discard_loan(loan);
      return false;
    }
    return rsg::dds::succeeded(writer->write(loan));
  };
  for (int i = 0; i < kWarmUp; ++i) ASSERT_TRUE(publish(frames[static_cast<std::size_t>(i) % frames.size()]));

  std::size_t written = 0;
  test::AllocationCounter allocations;
  allocations.resume();
  for (int i = 0; i < kMeasured; ++i) written += publish(frames[static_cast<std::size_t>(i) % frames.size()]);
  allocations.pause();
  EXPECT_EQ(written, static_cast<std::size_t>(kMeasured));
  EXPECT_EQ(allocations.total(), 0U) << "heap allocations on the publishing thread over " << kMeasured
                                     << " frames; rsg's first:\n"
                                     << allocations.first_by_rsg();

  // What is measured is the writing thread, so the reader only has to be matched. Receipt is
  // checked for UDP; a data-sharing reader in the same process as its writer is notified but
  // now and then finds no valid sample in Fast DDS 2.9.1 (about 1 run in 4 here; views tests saw
  // the same), so it is not asserted there.
  if (reader_data_sharing) return;
  EXPECT_TRUE(reader->wait_for_unread_message(rsg::dds::Duration(10, 0))) << "nothing reached the reader";
  RobotState received;
  fdds::SampleInfo info;
  EXPECT_EQ(reader->take_next_sample(&received, &info), rsg::dds::kOk);
}

// Not measured: a same-host reader that refuses data-sharing is served by Fast DDS 2.9's SHM
// transport, whose SharedMemTransport::copy_to_shared_buffer allocates ~3 times per send.
TEST(HotPath, DecodeLoanAndWriteToAUdpReaderAllocatesNothing) {
  expect_no_allocations_while_publishing("rsg_hot_path_udp", /*reader_data_sharing=*/false);
}

TEST(HotPath, DecodeLoanAndWriteToADataSharingReaderAllocatesNothing) {
  expect_no_allocations_while_publishing("", /*reader_data_sharing=*/true);
}

}  // namespace
}  // namespace rsg
