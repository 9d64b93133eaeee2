// A DDS domain participant that owns every entity created through it.
//
//   rsg::dds::Participant participant(domain, "rsg_participant");
//   auto* topic = participant.robot_state_topic("robot_state");
//   auto* writer = participant.publisher({"robot1"})->create_datawriter_with_profile(topic,
//   "rsg_state_writer");
//
// Entities are deleted, contained ones first, when the Participant goes out of scope. Its UDP
// transports sit behind rsg's guard (rsg/dds/rtps_guard.hpp): no datagram and no peer can make
// Fast DDS abort it.
#pragma once

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/qos/DomainParticipantQos.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>
#include <memory>
#include <string>
#include <vector>

#include "rsg/dds/discovery.hpp"
#include "rsg/dds/rtps_guard.hpp"
#include "rsg/error.hpp"

namespace rsg::dds {

class Participant {
 public:
  /// Creates the participant from an XML participant profile (load_profiles first), on `domain`;
  /// an empty profile name means Fast DDS's default participant QoS.
  /// @throws rsg::InputError when no such profile is loaded.
  /// @throws rsg::EnvironmentError when Fast DDS refuses the participant.
  Participant(int domain, const std::string& profile);
  /// Same, then finds the others through `discovery`'s servers or peers instead of multicast.
  /// A `listener` (e.g. WriterDirectory::listener()) hears discovery from the participant's first
  /// moment, with StatusMask::none(); it must outlive the participant.
  /// @throws rsg::InputError for an unknown profile or a bad server or peer.
  /// @throws rsg::EnvironmentError when Fast DDS refuses the participant.
  Participant(int domain, const std::string& profile, const DiscoveryOptions& discovery,
              eprosima::fastdds::dds::DomainParticipantListener* listener = nullptr);
  /// Creates the participant from explicit QoS.
  /// @throws rsg::EnvironmentError when Fast DDS refuses the participant.
  Participant(int domain, const eprosima::fastdds::dds::DomainParticipantQos& qos,
              eprosima::fastdds::dds::DomainParticipantListener* listener = nullptr);
  ~Participant();
  Participant(const Participant&) = delete;
  Participant& operator=(const Participant&) = delete;

  eprosima::fastdds::dds::DomainParticipant* get() const { return participant_; }

  /// What the transport guard did so far (for the gateway's /metrics).
  const RtpsGuardCounts& rtps_guard() const { return *guard_; }

  /// Registers `RobotState` (with its type object, which content filters need) and returns the
  /// topic of that name, creating it once. Type information is not sent in discovery: Cyclone DDS
  /// 0.10 silently drops samples of writers that announce it.
  /// A non-empty `type_name` registers the same type under that name instead (e.g. the ROS 2 name
  /// rsg::dds::kRos2RobotStateType): same plain type, same loans, and content filters still find it.
  eprosima::fastdds::dds::Topic* robot_state_topic(const std::string& name,
                                                   const std::string& type_name = {});
  /// Same for any other generated type (e.g. GatewayStatus); `type` is taken on first use.
  eprosima::fastdds::dds::Topic* topic(const std::string& name, eprosima::fastdds::dds::TypeSupport type);

  /// A publisher / subscriber in the given partitions (empty: the default partition).
  eprosima::fastdds::dds::Publisher* publisher(const std::vector<std::string>& partitions = {});
  eprosima::fastdds::dds::Subscriber* subscriber(const std::vector<std::string>& partitions = {});

 private:
  std::shared_ptr<RtpsGuardCounts> guard_ = std::make_shared<RtpsGuardCounts>();
  eprosima::fastdds::dds::DomainParticipant* participant_ = nullptr;
};

}  // namespace rsg::dds
