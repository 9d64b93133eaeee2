#include "rsg/dds/writer_directory.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace rsg {
namespace {

using dds::DiscoveredWriter;
using dds::explain_no_writer;
using dds::WantedWriter;

const WantedWriter kWanted{0, "robot_state", "rsg::RobotState", {"robot1"}};

std::string joined(const std::vector<std::string>& lines) {
  std::string text;
  for (const auto& line : lines) text += line + "\n";
  return text;
}

TEST(WriterDirectory, TheFirstLineSaysWhatTheReaderLooksFor) {
  const auto lines = explain_no_writer(kWanted, {});
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_EQ(lines[0],
            "no writer matched: this reader looks for topic 'robot_state', type 'rsg::RobotState', in "
            "partition 'robot1' on domain 0");
  EXPECT_EQ(
      lines[1],
      "no writer of any topic is visible on domain 0: is the gateway running, on this --domain, and can "
      "discovery reach it (multicast, --peer, --discovery-server, a security profile)?");
}

TEST(WriterDirectory, AWriterInAnotherPartitionIsNamedWithTheFlagThatMatchesIt) {
  const auto lines = explain_no_writer(kWanted, {{"robot_state", "rsg::RobotState", {"robot2"}},
                                                 {"rsg_gateway_status", "rsg::GatewayStatus", {"robot2"}}});
  ASSERT_EQ(lines.size(), 3u) << joined(lines);
  EXPECT_EQ(lines[1],
            "a writer of 'robot_state' (type 'rsg::RobotState') exists in partition 'robot2': another "
            "partition (--partition robot2)");
  EXPECT_EQ(lines[2], "1 other topic visible on domain 0: 'rsg_gateway_status'");
}

TEST(WriterDirectory, TheDefaultPartitionIsSaidInWords) {
  const auto lines = explain_no_writer(kWanted, {{"robot_state", "rsg::RobotState", {}}});
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_EQ(lines[1],
            "a writer of 'robot_state' (type 'rsg::RobotState') exists in the default partition: another "
            "partition (no --partition)");
}

TEST(WriterDirectory, AnotherTopicOrTypeOfTheSameDataIsNamed) {
  const auto lines =
      explain_no_writer(kWanted, {{"rt/robot1/robot_state", "rsg_msgs::msg::dds_::RobotState_", {"robot1"}},
                                  {"robot_state", "rsg_msgs::msg::dds_::RobotState_", {"robot1"}},
                                  {"arm", "rsg::RobotState", {"robot*"}}});
  ASSERT_EQ(lines.size(), 4u) << joined(lines);
  EXPECT_EQ(
      lines[1],
      "a writer of 'rt/robot1/robot_state' (type 'rsg_msgs::msg::dds_::RobotState_') exists in partition "
      "'robot1': ROS 2 names, as rsg_gateway --ros2 writes: rsg_echo --ros2 --ros2-namespace /robot1 reads "
      "it");
  EXPECT_EQ(
      lines[2],
      "a writer of 'robot_state' (type 'rsg_msgs::msg::dds_::RobotState_') exists in partition 'robot1': "
      "same topic and partition but another type, so they never match");
  // A partition pattern matches the reader's partition: only the topic differs.
  EXPECT_EQ(lines[3],
            "a writer of 'arm' (type 'rsg::RobotState') exists in partition 'robot*': another topic name "
            "(--topic arm)");
}

TEST(WriterDirectory, AReaderWithRos2NamesIsToldAboutAGatewayWithout) {
  const WantedWriter ros2{0, "rt/robot_state", "rsg_msgs::msg::dds_::RobotState_", {}};
  const auto lines = explain_no_writer(ros2, {{"robot_state", "rsg::RobotState", {"robot1"}}});
  ASSERT_EQ(lines.size(), 2u) << joined(lines);
  EXPECT_EQ(
      lines[1],
      "a writer of 'robot_state' (type 'rsg::RobotState') exists in partition 'robot1': rsg's own names, "
      "as rsg_gateway writes without --ros2 (--partition robot1)");
  const auto rooted =
      explain_no_writer(kWanted, {{"rt/robot_state", "rsg_msgs::msg::dds_::RobotState_", {}}});
  ASSERT_EQ(rooted.size(), 2u) << joined(rooted);
  EXPECT_EQ(
      rooted[1],
      "a writer of 'rt/robot_state' (type 'rsg_msgs::msg::dds_::RobotState_') exists in the default "
      "partition: ROS 2 names, as rsg_gateway --ros2 writes: rsg_echo --ros2 reads it (no --partition)");
}

TEST(WriterDirectory, AWriterThatShouldMatchButDoesNotPointsAtQosOrSecurity) {
  const auto lines = explain_no_writer(kWanted, {{"robot_state", "rsg::RobotState", {"robot1"}},
                                                 {"robot_state", "rsg::RobotState", {"robot1"}}});
  ASSERT_EQ(lines.size(), 2u) << joined(lines);  // the same writer twice is said once
  EXPECT_EQ(
      lines[1],
      "a writer of 'robot_state' (type 'rsg::RobotState') exists in partition 'robot1': same topic, type "
      "and partition, yet not matched: their QoS or security settings differ");
}

TEST(WriterDirectory, TwoParticipantsWritingOnePartitionAreSaidToBeMixed) {
  const DiscoveredWriter robot1{"robot_state", "rsg::RobotState", {"robot1"}, "01.0f.aa"};
  DiscoveredWriter robot2 = robot1;
  robot2.participant = "01.0f.bb";
  const auto lines = dds::explain_mixed_writers(kWanted, {robot1, robot2});
  ASSERT_EQ(lines.size(), 1u) << joined(lines);
  EXPECT_NE(lines[0].find("2 programs write 'robot_state' in partition 'robot1'"), std::string::npos)
      << lines[0];
  EXPECT_NE(lines[0].find("own partition"), std::string::npos) << lines[0];
}

TEST(WriterDirectory, OneParticipantPerPartitionIsNotMixed) {
  // Two writers of one participant (the gateway's state and a second writer of it), and a reader
  // of every partition that sees one robot in each.
  const DiscoveredWriter a{"robot_state", "rsg::RobotState", {"robot1"}, "01.0f.aa"};
  EXPECT_TRUE(dds::explain_mixed_writers(kWanted, {a, a}).empty());
  const WantedWriter every{0, "robot_state", "rsg::RobotState", {"*"}};
  DiscoveredWriter b = a;
  b.partitions = {"robot2"};
  b.participant = "01.0f.bb";
  EXPECT_TRUE(dds::explain_mixed_writers(every, {a, b}).empty());
  // Another topic in the same partition is not the reader's.
  DiscoveredWriter status = b;
  status.topic = "rsg_gateway_status";
  status.partitions = {"robot1"};
  EXPECT_TRUE(dds::explain_mixed_writers(kWanted, {a, status}).empty());
}

TEST(WriterDirectory, AGatewayCountsTheOtherParticipantsWritersOfItsTopicInItsPartition) {
  const DiscoveredWriter own{"robot_state", "rsg::RobotState", {"robot1"}, "01.0f.aa"};
  DiscoveredWriter other = own;
  other.participant = "01.0f.bb";
  DiscoveredWriter elsewhere = other;
  elsewhere.partitions = {"robot2"};
  DiscoveredWriter pattern = other;
  pattern.partitions = {"robot*"};
  EXPECT_EQ(dds::count_other_writers("robot_state", {"robot1"}, "01.0f.aa", {own}), 0u);
  EXPECT_EQ(dds::count_other_writers("robot_state", {"robot1"}, "01.0f.aa", {own, other, elsewhere}), 1u);
  EXPECT_EQ(dds::count_other_writers("robot_state", {"robot1"}, "01.0f.aa", {own, pattern}), 1u);
  EXPECT_EQ(dds::count_other_writers("robot_state_50hz", {"robot1"}, "01.0f.aa", {own, other}), 0u);
}

}  // namespace
}  // namespace rsg
