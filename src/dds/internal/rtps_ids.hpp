// INTERNAL, not part of rsg's API and not installed (src/dds/internal/).
//
// The RTPS numbers the screen and the discovery admission read (RTPS 2.5, 9.4.5.1.1 and 9.6.2.2.2;
// DDS Security 1.1, 7.3.6.1 and 7.4.1.3; eProsima's vendor ones), once.
#pragma once

#include <cstdint>

namespace rsg::dds::internal {

inline constexpr std::uint32_t kHeaderBytes = 20;  // "RTPS", version, vendor, GUID prefix
inline constexpr std::uint32_t kSubmessageHeaderBytes = 4;
inline constexpr std::uint32_t kStatisticsBodyBytes = 56;  // locator, timestamp, sequence
inline constexpr std::uint8_t kVendorEprosima[2] = {0x01, 0x0F};

// Submessage ids.
inline constexpr std::uint8_t kPad = 0x01;
inline constexpr std::uint8_t kAckNack = 0x06;
inline constexpr std::uint8_t kHeartbeat = 0x07;
inline constexpr std::uint8_t kGap = 0x08;
inline constexpr std::uint8_t kInfoTimestamp = 0x09;
inline constexpr std::uint8_t kInfoSource = 0x0c;
inline constexpr std::uint8_t kInfoReplyIp4 = 0x0d;
inline constexpr std::uint8_t kInfoDestination = 0x0e;
inline constexpr std::uint8_t kInfoReply = 0x0f;
inline constexpr std::uint8_t kNackFrag = 0x12;
inline constexpr std::uint8_t kHeartbeatFrag = 0x13;
inline constexpr std::uint8_t kData = 0x15;
inline constexpr std::uint8_t kDataFrag = 0x16;
inline constexpr std::uint8_t kSecBody = 0x30;
inline constexpr std::uint8_t kSecPrefix = 0x31;
inline constexpr std::uint8_t kSecPostfix = 0x32;
inline constexpr std::uint8_t kSrtpsPrefix = 0x33;
inline constexpr std::uint8_t kSrtpsPostfix = 0x34;
inline constexpr std::uint8_t kFlagEndianness = 0x01, kFlagInlineQos = 0x02, kFlagData = 0x04,
                              kFlagKey = 0x08;
inline constexpr std::uint8_t kFlagInvalidate = 0x02;  // INFO_TS: no time stamp follows
inline constexpr std::uint8_t kFlagMulticast = 0x02;   // INFO_REPLY(_IP4): a multicast list follows

// Parameter ids.
inline constexpr std::uint16_t kPidSentinel = 0x0001;
inline constexpr std::uint16_t kPidLeaseDuration = 0x0002;
inline constexpr std::uint16_t kPidTimeBasedFilter = 0x0004;
inline constexpr std::uint16_t kPidTopicName = 0x0005;
inline constexpr std::uint16_t kPidTypeName = 0x0007;
inline constexpr std::uint16_t kPidReliability = 0x001a;
inline constexpr std::uint16_t kPidLiveliness = 0x001b;
inline constexpr std::uint16_t kPidDeadline = 0x0023;
inline constexpr std::uint16_t kPidLatencyBudget = 0x0027;
inline constexpr std::uint16_t kPidPartition = 0x0029;
inline constexpr std::uint16_t kPidLifespan = 0x002b;
inline constexpr std::uint16_t kPidUserData = 0x002c;
inline constexpr std::uint16_t kPidGroupData = 0x002d;
inline constexpr std::uint16_t kPidTopicData = 0x002e;
inline constexpr std::uint16_t kPidUnicastLocator = 0x002f;
inline constexpr std::uint16_t kPidMulticastLocator = 0x0030;
inline constexpr std::uint16_t kPidDefaultUnicastLocator = 0x0031;
inline constexpr std::uint16_t kPidMetatrafficUnicastLocator = 0x0032;
inline constexpr std::uint16_t kPidMetatrafficMulticastLocator = 0x0033;
inline constexpr std::uint16_t kPidContentFilterProperty = 0x0035;
inline constexpr std::uint16_t kPidDefaultMulticastLocator = 0x0048;
inline constexpr std::uint16_t kPidPropertyList = 0x0059;
inline constexpr std::uint16_t kPidEntityName = 0x0062;
inline constexpr std::uint16_t kPidKeyHash = 0x0070;
inline constexpr std::uint16_t kPidStatusInfo = 0x0071;
inline constexpr std::uint16_t kPidDataRepresentation = 0x0073;
inline constexpr std::uint16_t kPidTypeInformation = 0x0075;
inline constexpr std::uint16_t kPidIdentityToken = 0x1001;
inline constexpr std::uint16_t kPidPermissionsToken = 0x1002;
inline constexpr std::uint16_t kPidIdentityStatusToken = 0x1006;
inline constexpr std::uint16_t kPidDataSharing = 0x8006;
// Standard parameters of fixed size (RTPS 2.5, 9.6.2.2.2; DDS Security 1.1, 7.4.1.6).
inline constexpr std::uint16_t kPidOwnershipStrength = 0x0006;
inline constexpr std::uint16_t kPidProtocolVersion = 0x0015;
inline constexpr std::uint16_t kPidVendorId = 0x0016;
inline constexpr std::uint16_t kPidDurability = 0x001d;
inline constexpr std::uint16_t kPidDurabilityService = 0x001e;
inline constexpr std::uint16_t kPidOwnership = 0x001f;
inline constexpr std::uint16_t kPidPresentation = 0x0021;
inline constexpr std::uint16_t kPidDestinationOrder = 0x0025;
inline constexpr std::uint16_t kPidHistory = 0x0040;
inline constexpr std::uint16_t kPidResourceLimits = 0x0041;
inline constexpr std::uint16_t kPidExpectsInlineQos = 0x0043;
inline constexpr std::uint16_t kPidTransportPriority = 0x0049;
inline constexpr std::uint16_t kPidParticipantGuid = 0x0050;
inline constexpr std::uint16_t kPidGroupGuid = 0x0052;
inline constexpr std::uint16_t kPidBuiltinEndpointSet = 0x0058;
inline constexpr std::uint16_t kPidEndpointGuid = 0x005a;
inline constexpr std::uint16_t kPidEndpointSecurityInfo = 0x1004;
inline constexpr std::uint16_t kPidParticipantSecurityInfo = 0x1005;
inline constexpr std::uint32_t kLocatorBytes = 24;  // kind, port, 16-byte address

// Built-in entity ids (RTPS 2.5, 9.3.1.4).
inline constexpr std::uint32_t kSpdpWriter = 0x000100c2, kSpdpReader = 0x000100c7;

}  // namespace rsg::dds::internal
