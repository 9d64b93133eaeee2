// Group views in one process: the shipped profiles mean what their names say, broken profiles are
// refused with a message naming the problem, and a reader on a view of groups S receives exactly
// the samples whose group_select contains all of S, unchanged.
#include "rsg/dds/views.hpp"

#include <RobotStatePubSubTypes.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/qos/DataWriterQos.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <map>
#include <memory>

#include "rsg/dds/participant.hpp"
#include "rsg/dds/profiles.hpp"
#include "rsg/dds/robot_state.hpp"
#include "tests/dds/mixed_stream.hpp"
#include "tests/support/test_domain.hpp"

namespace rsg {
namespace fdds = eprosima::fastdds::dds;
namespace {

// Profiles are process-wide in Fast DDS; load them once for every test of this binary.
class Views : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dds::load_profiles(dds::default_profiles_dir());
    dds::load_profiles(std::filesystem::path(RSG_VIEWS_TEST_DIR) / "broken_views.xml");
  }

  static int test_domain() { return rsg::test::test_domain(); }
};

TEST_F(Views, GroupFilterExpressionIsTheDocumentedDdsSql) {
  EXPECT_EQ(dds::group_filter_expression(0b000100), "group_present[2] = TRUE");
  EXPECT_EQ(dds::group_filter_expression(0b001100), "group_present[2] = TRUE AND group_present[3] = TRUE");
  EXPECT_EQ(dds::group_filter_expression(0b111111),
            "group_present[0] = TRUE AND group_present[1] = TRUE AND group_present[2] = TRUE AND "
            "group_present[3] = TRUE AND group_present[4] = TRUE AND group_present[5] = TRUE");
  EXPECT_THROW(dds::group_filter_expression(0), dds::ViewError);
  EXPECT_THROW(dds::group_filter_expression(0b1000000), dds::ViewError);
  EXPECT_EQ(dds::group_view(0b000101).name, "groups_0_2");
}

// Pins the shipped view names to the groups docs/protocol.md puts their fields in.
TEST_F(Views, ShippedViewsCarryTheGroupsTheirNamesSay) {
  dds::Participant participant(test_domain(), "rsg_participant");
  const fdds::Subscriber& subscriber = *participant.subscriber();
  const std::map<std::string, std::uint8_t> expected = {
      {"view_poses", 0b000001},      {"view_load_and_elbow", 0b000010},  {"view_joints", 0b000100},
      {"view_contact", 0b001000},    {"view_cartesian_motor", 0b010000}, {"view_status", 0b100000},
      {"view_kinematics", 0b000101}, {"view_forces", 0b001100},          {"view_full", 0b111111},
  };
  for (const auto& [profile, groups] : expected) {
    SCOPED_TRACE(profile);
    const dds::View view = dds::load_view(subscriber, profile);
    EXPECT_EQ(view.name, profile);
    EXPECT_EQ(view.groups, groups);
    EXPECT_EQ(view.filter, dds::group_filter_expression(groups));
  }
}

TEST_F(Views, FlavoursHaveTheDocumentedQos) {
  dds::Participant participant(test_domain(), "rsg_participant");
  const fdds::Subscriber& subscriber = *participant.subscriber();
  const fdds::DataReaderQos realtime = dds::load_reader_qos(subscriber, dds::kRealtimeReaderProfile);
  EXPECT_EQ(realtime.reliability().kind, fdds::BEST_EFFORT_RELIABILITY_QOS);
  EXPECT_EQ(realtime.history().kind, fdds::KEEP_LAST_HISTORY_QOS);
  EXPECT_EQ(realtime.history().depth, 1);
  EXPECT_EQ(realtime.deadline().period, dds::Duration(0, 100'000'000));
  const fdds::DataReaderQos logger = dds::load_reader_qos(subscriber, dds::kLoggerReaderProfile);
  EXPECT_EQ(logger.reliability().kind, fdds::RELIABLE_RELIABILITY_QOS);
  EXPECT_EQ(logger.history().kind, fdds::KEEP_LAST_HISTORY_QOS);
  EXPECT_EQ(logger.history().depth, 5000);
  EXPECT_EQ(logger.resource_limits().max_samples, 5000);
}

// The message must name the profile and the problem, since it ends up on an operator's terminal.
void expect_view_error(const fdds::Subscriber& subscriber, const std::string& profile,
                       const std::string& expected_part) {
  SCOPED_TRACE(profile);
  try {
    dds::load_view(subscriber, profile);
    ADD_FAILURE() << "accepted";
  } catch (const dds::ViewError& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("'" + profile + "'"), std::string::npos) << message;
    EXPECT_NE(message.find(expected_part), std::string::npos) << message;
  }
}

TEST_F(Views, UnusableProfilesAreRefusedClearly) {
  dds::Participant participant(test_domain(), "rsg_participant");
  const fdds::Subscriber& subscriber = *participant.subscriber();
  expect_view_error(subscriber, "view_no_such_thing", "no such data_reader profile");
  expect_view_error(subscriber, dds::kLoggerReaderProfile, "not a view");
  expect_view_error(subscriber, "broken_group_out_of_range", "'7' is not a group number 0..5");
  expect_view_error(subscriber, "broken_group_name", "'joints' is not a group number");
  expect_view_error(subscriber, "broken_groups_and_filter", "one or the other");
}

TEST_F(Views, RawFilterProfileKeepsItsExpression) {
  dds::Participant participant(test_domain(), "rsg_participant");
  const dds::View view = dds::load_view(*participant.subscriber(), "raw_filter_moving_joints");
  EXPECT_EQ(view.groups, 0);
  EXPECT_EQ(view.filter, "group_present[2] = TRUE AND robot_mode = 2");
}

TEST_F(Views, ReadersOfOneViewShareItsFilteredTopic) {
  dds::Participant participant(test_domain(), "rsg_participant");
  fdds::Subscriber& subscriber = *participant.subscriber();
  fdds::Topic& topic = *participant.robot_state_topic("robot_state");
  auto first =
      std::make_unique<dds::ViewReader>(subscriber, topic, "view_joints", dds::kRealtimeReaderProfile);
  dds::ViewReader second(subscriber, topic, "view_joints", dds::kLoggerReaderProfile);
  EXPECT_EQ(first->filtered_topic(), second.filtered_topic());
  EXPECT_EQ(second.filtered_topic()->get_name(), "robot_state/view_joints");
  first.reset();  // must leave the filtered topic to `second`
  EXPECT_EQ(participant.get()->lookup_topicdescription("robot_state/view_joints"), second.filtered_topic());
}

TEST_F(Views, ViewReadersReceiveExactlyTheSamplesCarryingAllTheirGroups) {
  dds::Participant participant(test_domain(), "rsg_participant");
  fdds::Topic& topic = *participant.robot_state_topic("robot_state");
  fdds::Subscriber& subscriber = *participant.subscriber();

  struct Case {
    std::unique_ptr<dds::ViewReader> reader;
    std::function<bool(const wire::StateValues&)> wants;
  };
  auto groups_filter = [](std::uint8_t groups) {
    return [groups](const wire::StateValues& values) { return values.selection.covers_groups(groups); };
  };
  std::vector<Case> cases;
  for (const char* profile : {"view_joints", "view_forces", "view_kinematics", "view_status", "view_full"}) {
    auto reader = std::make_unique<dds::ViewReader>(subscriber, topic, profile, dds::kLoggerReaderProfile);
    const std::uint8_t groups = reader->view().groups;
    cases.push_back({std::move(reader), groups_filter(groups)});
  }
  cases.push_back(
      {std::make_unique<dds::ViewReader>(subscriber, topic, dds::group_view(0b101000),
                                         dds::load_reader_qos(subscriber, dds::kLoggerReaderProfile)),
       groups_filter(0b101000)});
  cases.push_back({std::make_unique<dds::ViewReader>(subscriber, topic, "raw_filter_moving_joints",
                                                     dds::kLoggerReaderProfile),
                   [](const wire::StateValues& values) {
                     return values.selection.has_group(2) &&
                            values.selection.contains(wire::Field::robot_mode) &&
                            values.integer(wire::Field::robot_mode) == 2;
                   }});

  fdds::Publisher& publisher = *participant.publisher();
  fdds::DataWriterQos writer_qos = publisher.get_default_datawriter_qos();
  writer_qos.reliability().kind = fdds::RELIABLE_RELIABILITY_QOS;
  writer_qos.history().kind = fdds::KEEP_ALL_HISTORY_QOS;
  fdds::DataWriter* writer = publisher.create_datawriter(&topic, writer_qos);
  ASSERT_NE(writer, nullptr);
  ASSERT_TRUE(test::wait_for_matched_readers(*writer, static_cast<int>(cases.size())));

  const std::vector<wire::StateValues> stream = test::mixed_stream(4 * test::kAllGroupSubsets);
  RobotState sample;
  for (const wire::StateValues& values : stream) {
    dds::to_sample(values, sample);
    ASSERT_TRUE(dds::succeeded(writer->write(&sample)));
  }
  ASSERT_EQ(writer->wait_for_acknowledgments(rsg::dds::Duration(60, 0)), rsg::dds::kOk);

  for (Case& test_case : cases) {
    SCOPED_TRACE(test_case.reader->view().name);
    std::vector<std::size_t> expected;
    for (std::size_t i = 0; i < stream.size(); ++i)
      if (test_case.wants(stream[i])) expected.push_back(i);
    ASSERT_FALSE(expected.empty()) << "the stream does not exercise this view";

    std::vector<std::size_t> received;
    fdds::SampleInfo info;
    while (test_case.reader->get()->take_next_sample(&sample, &info) == rsg::dds::kOk) {
      // Writer sequence numbers start at 1 and follow the write order.
      const auto index = static_cast<std::size_t>(info.sample_identity.sequence_number().to64long() - 1);
      ASSERT_LT(index, stream.size());
      received.push_back(index);
      wire::StateValues values;
      dds::to_values(sample, values);
      EXPECT_TRUE(values == stream[index]) << "sample " << index << " changed on the way";
    }
    EXPECT_EQ(received, expected);
  }
}

}  // namespace
}  // namespace rsg
