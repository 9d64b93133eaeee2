// The ROS 2 standard topics' writers are created like every other writer of the gateway
// (gateway/entities.hpp): no reader's content filter runs in them, so no reader can make the
// gateway evaluate its expression (docs/operating.md, "rsg's writers evaluate no reader's filter").
#include <gtest/gtest.h>

#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/qos/DataWriterQos.hpp>

#include "gateway/ros2_standard_topics.hpp"
#include "rsg/dds/participant.hpp"
#include "tests/support/test_domain.hpp"

namespace rsg::gateway {
namespace {

using namespace std::chrono_literals;

TEST(Ros2StandardTopicsWriters, LeaveFilteringToTheReaders) {
  dds::Participant participant(rsg::test::test_domain(), "");
  Ros2StandardTopics::Options options;
  options.joint_states = Ros2StandardTopics::Output{{1, {}}, "qos_joint_states"};
  options.tf = Ros2StandardTopics::Output{{0, 10ms}, "qos_tf"};
  options.external_wrench = Ros2StandardTopics::Output{{2, {}}, "qos_wrench"};
  options.joint_names = {"j1", "j2", "j3", "j4", "j5", "j6", "j7"};
  options.base_frame = options.wrench_frame = "base";
  options.ee_frame = "ee";
  Ros2StandardTopics topics(participant, *participant.publisher(), options);

  ASSERT_EQ(topics.writers().size(), 3U);
  for (const auto* writer : topics.writers()) {
    const auto& filters = writer->get_qos().writer_resource_limits().reader_filters_allocation;
    EXPECT_EQ(filters.initial, 0U) << writer->get_topic()->get_name();
    EXPECT_EQ(filters.maximum, 0U) << writer->get_topic()->get_name() << " keeps slots for reader filters";
  }
}

}  // namespace
}  // namespace rsg::gateway
