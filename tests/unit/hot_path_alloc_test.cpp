// The ingress hot path (frame in -> decode -> loaned sample -> write) allocates nothing in
// steady state. Counts operator new calls made by this thread over 10,000 frames after warm-up.
#include <RobotStatePubSubTypes.h>
#include <fastrtps/xmlparser/XMLProfileManager.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <cstdlib>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/qos/DataWriterQos.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/qos/DataReaderQos.hpp>
#include <new>
#include <random>
#include <thread>

#include "random_state.hpp"
#include "rsg/frame.hpp"
#include "rsg/participant.hpp"
#include "rsg/profiles.hpp"
#include "rsg/robot_state.hpp"

namespace {
// Only the test thread counts; Fast DDS's own threads (discovery, timers) are not the hot path.
thread_local bool counting = false;
thread_local std::size_t allocations = 0;
}  // namespace

void* operator new(std::size_t size) {
  if (counting) ++allocations;
  if (void* p = std::malloc(size ? size : 1)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t size) { return operator new(size); }
void* operator new(std::size_t size, std::align_val_t alignment) {
  if (counting) ++allocations;
  const std::size_t a = static_cast<std::size_t>(alignment);
  if (void* p = std::aligned_alloc(a, (size + a - 1) / a * a)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }

namespace rsg {
namespace {

constexpr int kWarmUp = 1'000;
constexpr int kMeasured = 10'000;

std::vector<std::vector<std::uint8_t>> make_frames(int count) {
  std::mt19937_64 rng(5);
  std::vector<std::vector<std::uint8_t>> frames;
  for (int i = 0; i < count; ++i) {
    StateValues values = test::random_state(rng);
    values.packet_number = static_cast<std::uint8_t>(i % 16);
    std::vector<std::uint8_t> frame(kMaxFrameBytes);
    frame.resize(
        encode(values.packet_number, values.selection, values.storage(), StateValues::layout(), frame).size);
    frames.push_back(std::move(frame));
  }
  return frames;
}

TEST(HotPath, DecodeIntoASampleAllocatesNothing) {
  const auto frames = make_frames(64);
  RobotState sample;
  std::size_t decoded = 0;
  counting = true;
  allocations = 0;
  for (int i = 0; i < kMeasured; ++i) {
    const DecodeResult result = decode(frames[static_cast<std::size_t>(i) % frames.size()]);
    if (result) to_sample(result.frame(), sample), ++decoded;
  }
  counting = false;
  EXPECT_EQ(decoded, static_cast<std::size_t>(kMeasured));
  EXPECT_EQ(allocations, 0U);
}

void expect_no_allocations_while_publishing(const std::string& profile, bool reader_data_sharing) {
  // A reader in a second participant and no intra-process shortcut, so the measured writes really
  // reach another participant through a transport or data-sharing.
  eprosima::fastrtps::LibrarySettingsAttributes settings;
  settings.intraprocess_delivery = eprosima::fastrtps::INTRAPROCESS_OFF;
  eprosima::fastrtps::xmlparser::XMLProfileManager::library_settings(settings);
  const int domain = static_cast<int>(::getpid() % 200 + 10);
  load_profiles(std::filesystem::path(RSG_TEST_DATA_DIR) / "hot_path_profiles.xml");
  Participant publishing(domain, profile);
  Participant subscribing(domain, profile);

  fdds::DataWriterQos qos = fdds::DATAWRITER_QOS_DEFAULT;
  qos.history().kind = fdds::KEEP_LAST_HISTORY_QOS;
  qos.history().depth = 1;
  qos.reliability().kind = fdds::BEST_EFFORT_RELIABILITY_QOS;
  qos.endpoint().history_memory_policy = eprosima::fastrtps::rtps::PREALLOCATED_MEMORY_MODE;
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
  fdds::PublicationMatchedStatus matched;
  for (int i = 0; i < 500 && matched.current_count == 0; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    writer->get_publication_matched_status(matched);
  }
  ASSERT_EQ(matched.current_count, 1) << "the reader never matched";

  const auto frames = make_frames(64);
  auto publish = [&](const std::vector<std::uint8_t>& frame) {
    const DecodeResult result = decode(frame);
    if (!result) return false;
    void* loan = nullptr;
    if (writer->loan_sample(loan) != ReturnCode_t::RETCODE_OK) return false;
    to_sample(result.frame(), *static_cast<RobotState*>(loan));
    return writer->write(loan);
  };
  for (int i = 0; i < kWarmUp; ++i) ASSERT_TRUE(publish(frames[static_cast<std::size_t>(i) % frames.size()]));

  std::size_t written = 0;
  counting = true;
  allocations = 0;
  for (int i = 0; i < kMeasured; ++i) written += publish(frames[static_cast<std::size_t>(i) % frames.size()]);
  counting = false;
  EXPECT_EQ(written, static_cast<std::size_t>(kMeasured));
  EXPECT_EQ(allocations, 0U) << "heap allocations on the ingress thread over " << kMeasured << " frames";

  RobotState received;
  fdds::SampleInfo info;
  EXPECT_EQ(reader->take_next_sample(&received, &info), ReturnCode_t::RETCODE_OK)
      << "nothing reached the reader";
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
