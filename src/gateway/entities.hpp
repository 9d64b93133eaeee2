// Every DataWriter and DataReader of the gateway is created here, so that what no profile may
// change holds for all of them:
// - no reader's content filter runs in the gateway (README, promise 2; docs/operating.md, "rsg's
//   writers evaluate no reader's filter"): every writer leaves filtering to the readers
//   (rsg::dds::leave_filtering_to_readers), so no reader can make the gateway evaluate its
//   expression, on the ingress thread or any other;
// - with --data-sharing off, no entity shares memory with a same-host peer (docs/security.md,
//   "Same-host processes"): Fast DDS 2.9.1 opens a data-sharing peer's segment in /dev/shm and
//   trusts its contents, so a local process that can write its own segment can abort the gateway;
// - the ROS 2 type hash is announced for the types that have one.
// Ros2StandardTopicsWriters.LeaveFilteringToTheReaders and integration.shm_attacks check the result.
#pragma once

#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <string>

#include "gateway/data_sharing.hpp"
#include "gateway/ros2_type_hash.hpp"
#include "rsg/dds/fastdds.hpp"
#include "rsg/dds/views.hpp"

namespace rsg::gateway {

/// create_datawriter with `qos`, the topic type's ROS 2 hash announced when it has one, content
/// filtering left to the readers, and data-sharing off when `sharing` says so.
/// @return nullptr when Fast DDS refuses the writer.
inline eprosima::fastdds::dds::DataWriter* create_writer(eprosima::fastdds::dds::Publisher& publisher,
                                                         eprosima::fastdds::dds::Topic* topic,
                                                         eprosima::fastdds::dds::DataWriterQos qos,
                                                         DataSharing sharing) {
  announce_ros2_type_hash(qos.user_data(), topic->get_type_name());
  rsg::dds::leave_filtering_to_readers(qos);
  if (sharing == DataSharing::kOff) qos.data_sharing().off();
  return publisher.create_datawriter(topic, qos);
}

/// create_writer with the QoS of the XML profile `profile`.
/// @return nullptr when the profile is unknown or Fast DDS refuses the writer.
inline eprosima::fastdds::dds::DataWriter* create_writer_with_profile(
    eprosima::fastdds::dds::Publisher& publisher, eprosima::fastdds::dds::Topic* topic,
    const std::string& profile, DataSharing sharing) {
  eprosima::fastdds::dds::DataWriterQos qos;
  if (publisher.get_datawriter_qos_from_profile(profile, qos) != rsg::dds::kOk) return nullptr;
  return create_writer(publisher, topic, qos, sharing);
}

/// create_datareader with the QoS of the XML profile `profile`, the topic type's ROS 2 hash
/// announced when it has one, and data-sharing off when `sharing` says so.
/// @return nullptr when the profile is unknown or Fast DDS refuses the reader.
inline eprosima::fastdds::dds::DataReader* create_reader_with_profile(
    eprosima::fastdds::dds::Subscriber& subscriber, eprosima::fastdds::dds::Topic* topic,
    const std::string& profile, DataSharing sharing) {
  eprosima::fastdds::dds::DataReaderQos qos;
  if (subscriber.get_datareader_qos_from_profile(profile, qos) != rsg::dds::kOk) return nullptr;
  announce_ros2_type_hash(qos.user_data(), topic->get_type_name());
  if (sharing == DataSharing::kOff) qos.data_sharing().off();
  return subscriber.create_datareader(topic, qos);
}

}  // namespace rsg::gateway
