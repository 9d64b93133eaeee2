// No reader's content filter runs in the gateway (README, promise 2; docs/operating.md, "rsg's
// writers evaluate no reader's filter"): every DataWriter the gateway creates leaves filtering to
// the readers (rsg::dds::leave_filtering_to_readers), so that no reader can make the gateway evaluate
// its expression, on the ingress thread or any other. Every writer of the gateway is created here;
// Ros2StandardTopicsWriters.LeaveFilteringToTheReaders checks the QoS that results.
#pragma once

#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <string>

#include "gateway/ros2_type_hash.hpp"
#include "rsg/dds/fastdds.hpp"
#include "rsg/dds/views.hpp"

namespace rsg::gateway {

/// create_datawriter with `qos`, the topic type's ROS 2 hash announced when it has one, and content
/// filtering left to the readers.
/// @return nullptr when Fast DDS refuses the writer.
inline eprosima::fastdds::dds::DataWriter* create_writer(eprosima::fastdds::dds::Publisher& publisher,
                                                         eprosima::fastdds::dds::Topic* topic,
                                                         eprosima::fastdds::dds::DataWriterQos qos) {
  announce_ros2_type_hash(qos.user_data(), topic->get_type_name());
  rsg::dds::leave_filtering_to_readers(qos);
  return publisher.create_datawriter(topic, qos);
}

/// create_writer with the QoS of the XML profile `profile`.
/// @return nullptr when the profile is unknown or Fast DDS refuses the writer.
inline eprosima::fastdds::dds::DataWriter* create_writer_with_profile(
    eprosima::fastdds::dds::Publisher& publisher, eprosima::fastdds::dds::Topic* topic,
    const std::string& profile) {
  eprosima::fastdds::dds::DataWriterQos qos;
  if (publisher.get_datawriter_qos_from_profile(profile, qos) != rsg::dds::kOk) return nullptr;
  return create_writer(publisher, topic, qos);
}

}  // namespace rsg::gateway
