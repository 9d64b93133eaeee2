// INTERNAL, not part of rsg's API and not installed (src/dds/internal/).
#pragma once

#include <cstddef>
#include <fastdds/dds/domain/qos/DomainParticipantQos.hpp>
#include <memory>

#include "rsg/dds/rtps_guard.hpp"

namespace rsg::dds::internal {

/// Puts every UDP transport `qos` would give its participant behind rsg's guard (Fast DDS's
/// ChainingTransport): the built-in ones become explicit (UDPv4 and shared memory, configured as
/// Fast DDS configures its built-ins), user UDPv4/UDPv6 descriptors are wrapped. TCP and shared
/// memory are left as they are (docs/fastdds-versions.md says why).
void guard_transports(eprosima::fastdds::dds::DomainParticipantQos& qos,
                      std::shared_ptr<RtpsGuardCounts> counts);

/// How much of other participants' discovery data a participant keeps, where `qos` leaves it
/// unbounded (Fast DDS's default): spoofed announcements, each a new participant with the longest
/// lease, would otherwise grow the process without end (docs/configuration.md, "Limits"). The bytes
/// of user data, partitions and properties of each are the screen's (kMaxAnnouncedUserDataBytes...).
inline constexpr std::size_t kMaxRemoteParticipants = 256;
inline constexpr std::size_t kMaxEndpointsPerRemoteParticipant = 128;  ///< readers, and writers
void bound_discovery(eprosima::fastdds::dds::DomainParticipantQos& qos);

}  // namespace rsg::dds::internal
