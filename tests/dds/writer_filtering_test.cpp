// Where a view's filter is evaluated, measured on the wire: the publishing participant's transport
// records the sequence number of every user sample it sends. A writer whose participant knows the
// view's filter class filters for a remote UDP reader (only the samples the view accepts are sent);
// it stops doing so when writer filtering is disabled (rsg::dds::leave_filtering_to_readers, what
// rsg's own writers do) or the writer's liveliness lease is finite (Fast DDS only filters for
// writers with infinite liveliness: docs "Conditions for writer side filtering"). Either way the
// reader gets exactly the samples its view accepts.
//
// Two participants in one process, intra-process delivery off, so that the reader is remote to
// the writer in every respect but the process.
#include <RobotStatePubSubTypes.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/qos/DataWriterQos.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>

#include "dds/internal/fastdds_compat.hpp"  // disable_intraprocess_delivery
#include "rsg/dds/group_filter.hpp"
#include "rsg/dds/participant.hpp"
#include "rsg/dds/profiles.hpp"
#include "rsg/dds/robot_state.hpp"
#include "rsg/dds/views.hpp"
#include "tests/dds/mixed_stream.hpp"
#include "tests/dds/sent_data_recorder.hpp"
#include "tests/support/test_domain.hpp"

namespace rsg {
namespace fdds = eprosima::fastdds::dds;
namespace {

constexpr std::uint8_t kForces = 0b001100;  // groups 2 and 3: view_forces

// A participant with the given sole transport, through Participant's "default QoS" profile.
std::unique_ptr<dds::Participant> participant_with(
    std::shared_ptr<eprosima::fastdds::rtps::TransportDescriptorInterface> transport, int domain) {
  auto* factory = fdds::DomainParticipantFactory::get_instance();
  fdds::DomainParticipantQos qos = fdds::PARTICIPANT_QOS_DEFAULT;
  qos.transport().use_builtin_transports = false;
  qos.transport().user_transports.push_back(std::move(transport));
  factory->set_default_participant_qos(qos);
  auto participant = std::make_unique<dds::Participant>(domain, "");
  factory->set_default_participant_qos(fdds::PARTICIPANT_QOS_DEFAULT);
  return participant;
}

struct Outcome {
  std::set<std::int64_t> sent;      // writer sequence numbers put on the wire
  std::set<std::int64_t> received;  // writer sequence numbers the view's reader got
  std::set<std::int64_t> accepted;  // writer sequence numbers of the samples the view accepts
  std::size_t written = 0;
};

enum class Delivery { kUdp, kDataSharing };
enum class WriterKnowsGroupFilter { kNo, kYes };

Outcome publish_mixed_stream_to_a_view(const fdds::DataWriterQos& base_writer_qos, Delivery delivery,
                                       WriterKnowsGroupFilter knows = WriterKnowsGroupFilter::kYes) {
  dds::internal::disable_intraprocess_delivery();
  dds::load_profiles(dds::default_profiles_dir());
  const int domain = rsg::test::test_domain();

  auto sent = std::make_shared<test::SentSamples>();
  auto publishing =
      participant_with(std::make_shared<test::SentDataRecordingTransportDescriptor>(sent), domain);
  auto subscribing =
      participant_with(std::make_shared<eprosima::fastdds::rtps::UDPv4TransportDescriptor>(), domain);
  if (knows == WriterKnowsGroupFilter::kYes) dds::register_group_filter(*publishing->get());

  // Reliable, so that nothing is lost in the burst; a repair resends a sequence number already
  // recorded, and samples filtered out are announced as GAPs, not sent as DATA.
  fdds::Subscriber& subscriber = *subscribing->subscriber();
  fdds::DataReaderQos reader_qos = dds::load_reader_qos(subscriber, dds::kLoggerReaderProfile);
  if (delivery == Delivery::kDataSharing) {
    reader_qos.data_sharing().automatic();
  } else {
    reader_qos.data_sharing().off();
  }
  dds::ViewReader reader(subscriber, *subscribing->robot_state_topic("robot_state"), dds::group_view(kForces),
                         reader_qos);

  fdds::DataWriterQos writer_qos = base_writer_qos;
  writer_qos.reliability().kind = fdds::RELIABLE_RELIABILITY_QOS;
  writer_qos.history().kind = fdds::KEEP_ALL_HISTORY_QOS;
  writer_qos.data_sharing().automatic();
  fdds::DataWriter* writer =
      publishing->publisher()->create_datawriter(publishing->robot_state_topic("robot_state"), writer_qos);
  EXPECT_NE(writer, nullptr);
  if (writer == nullptr) return {};
  EXPECT_TRUE(test::wait_for_matched_readers(*writer, 1));

  Outcome outcome;
  const std::vector<wire::StateValues> stream = test::mixed_stream(4 * test::kAllGroupSubsets);
  RobotState sample;
  for (std::size_t i = 0; i < stream.size(); ++i) {
    dds::to_sample(stream[i], sample);
    EXPECT_TRUE(dds::succeeded(writer->write(&sample)));
    if (stream[i].selection.covers_groups(kForces)) outcome.accepted.insert(static_cast<std::int64_t>(i + 1));
  }
  outcome.written = stream.size();

  // Take before waiting for acknowledgements: a data-sharing reader acknowledges on take.
  // The waits are a guard against hanging (a minute), not a threshold.
  fdds::SampleInfo info;
  for (int waits = 0; waits < 60 && outcome.received.size() < outcome.accepted.size(); ++waits) {
    reader->wait_for_unread_message(rsg::dds::Duration(1, 0));
    while (reader->take_next_sample(&sample, &info) == rsg::dds::kOk)
      outcome.received.insert(info.sample_identity.sequence_number().to64long());
  }
  EXPECT_EQ(writer->wait_for_acknowledgments(rsg::dds::Duration(60, 0)), rsg::dds::kOk);
  while (reader->take_next_sample(&sample, &info) == rsg::dds::kOk)  // nothing more may come
    outcome.received.insert(info.sample_identity.sequence_number().to64long());
  outcome.sent = sent->sequence_numbers();
  return outcome;
}

TEST(WriterSideFiltering, WriterSendsARemoteUdpViewOnlyTheSamplesItAccepts) {
  const Outcome outcome = publish_mixed_stream_to_a_view(fdds::DATAWRITER_QOS_DEFAULT, Delivery::kUdp);
  ASSERT_LT(outcome.accepted.size(), outcome.written);
  EXPECT_EQ(outcome.sent, outcome.accepted) << "the writer put rejected samples on the wire";
  EXPECT_EQ(outcome.received, outcome.accepted);
}

TEST(WriterSideFiltering, WithoutReaderFilterSlotsTheWriterSendsEverything) {
  fdds::DataWriterQos qos = fdds::DATAWRITER_QOS_DEFAULT;
  qos.writer_resource_limits().reader_filters_allocation.maximum = 0;
  const Outcome outcome = publish_mixed_stream_to_a_view(qos, Delivery::kUdp);
  EXPECT_EQ(outcome.sent.size(), outcome.written);
  EXPECT_EQ(outcome.received, outcome.accepted) << "the reader must filter instead";
}

// Why rsg_gateway's rsg_state_writer keeps the default, infinite liveliness.
TEST(WriterSideFiltering, AWriterWithFiniteLivelinessSendsEverything) {
  fdds::DataWriterQos qos = fdds::DATAWRITER_QOS_DEFAULT;
  qos.liveliness().kind = fdds::AUTOMATIC_LIVELINESS_QOS;
  qos.liveliness().lease_duration = rsg::dds::Duration(2, 0);
  qos.liveliness().announcement_period = rsg::dds::Duration(1, 0);
  const Outcome outcome = publish_mixed_stream_to_a_view(qos, Delivery::kUdp);
  EXPECT_EQ(outcome.sent.size(), outcome.written);
  EXPECT_EQ(outcome.received, outcome.accepted) << "the reader must filter instead";
}

// A writer that does not know the group filter class (an older rsg, another vendor) cannot
// evaluate it: it sends everything and the reader filters.
TEST(WriterSideFiltering, AWriterWithoutTheGroupFilterClassSendsEverything) {
  const Outcome outcome = publish_mixed_stream_to_a_view(fdds::DATAWRITER_QOS_DEFAULT, Delivery::kUdp,
                                                         WriterKnowsGroupFilter::kNo);
  EXPECT_EQ(outcome.sent.size(), outcome.written);
  EXPECT_EQ(outcome.received, outcome.accepted) << "the reader must filter instead";
}

// The QoS the gateway really publishes with (xml_profiles/gateway.xml, then
// leave_filtering_to_readers): no filter runs in the writer, the view's reader filters.
TEST(WriterSideFiltering, TheGatewayWriterLeavesFilteringToTheReaders) {
  dds::internal::disable_intraprocess_delivery();  // before `any`: Fast DDS 3 ignores it after a participant
  dds::load_profiles(dds::default_profiles_dir());
  dds::Participant any(rsg::test::test_domain(), "");
  fdds::DataWriterQos gateway_qos;
  ASSERT_EQ(any.publisher()->get_datawriter_qos_from_profile("rsg_state_writer", gateway_qos), rsg::dds::kOk);
  dds::leave_filtering_to_readers(gateway_qos);
  const Outcome outcome = publish_mixed_stream_to_a_view(gateway_qos, Delivery::kUdp);
  ASSERT_LT(outcome.accepted.size(), outcome.written);
  EXPECT_EQ(outcome.sent.size(), outcome.written) << "the gateway's writer evaluated a reader's filter";
  EXPECT_EQ(outcome.received, outcome.accepted);
}

// Data-sharing readers read the writer's history in shared memory: nothing goes through the
// transport, and the reader evaluates the filter itself (DataWriterImpl::process_reader_filter_info
// skips readers that are data-sharing compatible).
// Disabled: in about one run in three (seen under ctest) the data-sharing reader in the same
// process receives nothing at all, a delivery problem unrelated to filtering that is not yet
// understood. Run with --gtest_also_run_disabled_tests.
TEST(WriterSideFiltering, DISABLED_ADataSharingViewFiltersInTheReader) {
  const Outcome outcome =
      publish_mixed_stream_to_a_view(fdds::DATAWRITER_QOS_DEFAULT, Delivery::kDataSharing);
  EXPECT_TRUE(outcome.sent.empty()) << "samples went through the transport";
  EXPECT_EQ(outcome.received, outcome.accepted);
}

}  // namespace
}  // namespace rsg
