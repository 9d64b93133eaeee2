// INTERNAL, not part of rsg's API and not installed (src/dds/internal/): rsg's own sources, tools
// and tests include it as "dds/internal/fastdds_compat.hpp". Its names may change in any release.
//
// The one place where Fast DDS 2.x and 3.x differ for rsg (docs/fastdds-versions.md), together with
// the public rsg/dds/fastdds.hpp it includes: the names a user of rsg's API needs too (return
// codes, Duration, the rtps namespace, succeeded, RSG_FASTDDS_MAJOR) are there; what only rsg
// needs is here.
//
// rsg builds against Fast DDS 2.x (package `fastrtps`: Debian 12's 2.9.1, ROS 2 Jazzy's 2.14) or 3.x
// (package `fastdds`: Debian 13's 3.1, ROS 2 Kilted's 3.2), whichever CMake finds. The DDS API of
// `fastdds/dds/` is the same in both; what moved (the `eprosima::fastrtps` namespace, the return
// codes, `.h` -> `.hpp` RTPS headers, TopicDataType's members, the library settings, discovery
// servers) is named here once, and the rest of the tree uses these names:
//
//   rsg::dds::kOk, kBadParameter, Duration, kInfinite, rtps, succeeded   (rsg/dds/fastdds.hpp)
//   rsg::dds::internal::serialize, deserialize, max_serialized_size, is_plain, rename_type
//   rsg::dds::internal::is_keyed, disable_intraprocess_delivery, read_plain_samples_in_place
//   rsg::dds::internal::load_xml_profiles_file, DiscoveryProtocol
//   rsg::dds::internal::add_discovery_server, discovery_server_locator, discovery_server_prefix
//
// fastddsgen 4 names its files .hpp and registers TypeObjects by itself: src/dds/CMakeLists.txt puts
// forwarding headers with fastddsgen 2's names next to its output (RobotState.h, ...PubSubTypes.h,
// ...TypeObject.h with an empty registerRobotStateTypes()).
//
// Data representation: Fast DDS 3 writes XCDR1 unless told otherwise, which is what Fast DDS 2.x,
// Cyclone DDS 0.10 and rmw_fastrtps read; rsg states it in the profiles (xml_profiles/rsg.xml) and
// serializes XCDR1 here, so both builds put the same bytes on the wire.
#pragma once

#include <array>
#include <cstdint>
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/domain/qos/DomainParticipantQos.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/subscriber/qos/DataReaderQos.hpp>
#include <fastdds/dds/topic/TopicDataType.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>
#include <fstream>
#include <iterator>
#include <regex>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>

#include "rsg/dds/fastdds.hpp"

#if RSG_FASTDDS_MAJOR >= 3
#include <fastdds/LibrarySettings.hpp>
#include <fastdds/dds/xtypes/type_representation/TypeObject.hpp>
#include <fastdds/rtps/attributes/PropertyPolicy.hpp>
#include <fastdds/rtps/common/SerializedPayload.hpp>
#include <fastdds/utils/IPLocator.hpp>
#else
#include <fastdds/rtps/attributes/PropertyPolicy.h>
#include <fastdds/rtps/attributes/ServerAttributes.h>
#include <fastdds/rtps/common/SerializedPayload.h>
#include <fastrtps/attributes/LibrarySettingsAttributes.h>
#include <fastrtps/types/TypeObjectFactory.h>
#include <fastrtps/utils/IPLocator.h>
#include <fastrtps/xmlparser/XMLProfileManager.h>
#endif

namespace rsg::dds::internal {

#if RSG_FASTDDS_MAJOR >= 3

using DiscoveryProtocol = rtps::DiscoveryProtocol;

/// `original` under another name, announcing no TypeInformation: see rename_type().
class RenamedType final : public eprosima::fastdds::dds::TopicDataType {
 public:
  RenamedType(eprosima::fastdds::dds::TypeSupport original, const std::string& name)
      : original_(std::move(original)) {
    set_name(name);
    max_serialized_type_size = original_->max_serialized_type_size;
    is_compute_key_provided = original_->is_compute_key_provided;
  }

  bool serialize(const void* const data, rtps::SerializedPayload_t& payload,
                 eprosima::fastdds::dds::DataRepresentationId_t representation) override {
    return original_->serialize(data, payload, representation);
  }
  bool deserialize(rtps::SerializedPayload_t& payload, void* data) override {
    return original_->deserialize(payload, data);
  }
  std::uint32_t calculate_serialized_size(
      const void* const data, eprosima::fastdds::dds::DataRepresentationId_t representation) override {
    return original_->calculate_serialized_size(data, representation);
  }
  void* create_data() override { return original_->create_data(); }
  void delete_data(void* data) override { original_->delete_data(data); }
  bool compute_key(rtps::SerializedPayload_t& payload, rtps::InstanceHandle_t& handle,
                   bool force_md5) override {
    return original_->compute_key(payload, handle, force_md5);
  }
  bool compute_key(const void* const data, rtps::InstanceHandle_t& handle, bool force_md5) override {
    return original_->compute_key(data, handle, force_md5);
  }
  bool is_bounded() const override { return original_->is_bounded(); }
  bool is_plain(eprosima::fastdds::dds::DataRepresentationId_t representation) const override {
    return original_->is_plain(representation);
  }
  bool construct_sample(void* memory) const override { return original_->construct_sample(memory); }
  /// The original's TypeObject goes into the registry under its own name and, for the DDS-SQL filter
  /// factory (which looks it up by the topic's type name), under this one, unless that name is taken
  /// (in a ROS 2 process by rosidl's type, in which filters find the same members by the same bytes).
  /// This type keeps no type identifiers, so its endpoints announce no TypeInformation.
  void register_type_object_representation() override {
    namespace xtypes = eprosima::fastdds::dds::xtypes;
    original_->register_type_object_representation();
    auto& registry = eprosima::fastdds::dds::DomainParticipantFactory::get_instance()->type_object_registry();
    xtypes::TypeIdentifierPair ids;
    if (registry.get_type_identifiers(get_name(), ids) == kOk) return;
    const xtypes::TypeIdentifierPair& original = original_->type_identifiers();
    const xtypes::TypeIdentifier& complete = original.type_identifier1()._d() == xtypes::EK_COMPLETE
                                                 ? original.type_identifier1()
                                                 : original.type_identifier2();
    xtypes::TypeObject object;
    if (registry.get_type_object(complete, object) == kOk && object._d() == xtypes::EK_COMPLETE)
      registry.register_type_object(get_name(), object.complete(), ids);
  }

 private:
  eprosima::fastdds::dds::TypeSupport original_;
};

/// Gives `type` another registered name (the ROS 2 mangled name, a user's --type-name), under which
/// its endpoints match by type name alone, as on Fast DDS 2: they announce no TypeInformation. The
/// name belongs to a type defined elsewhere (rosidl's rsg_msgs/msg/RobotState) whose TypeObject
/// differs from the IDL's (its members are the .msg's lower-case names), and Fast DDS 3 matches two
/// endpoints that both announce TypeInformation only when their type identifiers are equal: an rclpy
/// subscription would never match. The samples are the same bytes, and DDS-SQL filters on the new
/// name read the original's members.
inline void rename_type(eprosima::fastdds::dds::TypeSupport& type, const std::string& name) {
  type = eprosima::fastdds::dds::TypeSupport(new RenamedType(std::move(type), name));
}

/// Loads an XML profile file written for Fast DDS 2 (rsg's xml_profiles/) or 3. Fast DDS 3 renamed
/// the elements of a writer's and a reader's <times> to snake case and lists discovery servers as
/// bare locators, and rejects the old forms, which Fast DDS 2 needs: they are rewritten here before
/// Fast DDS 3 parses the file.
inline ReturnCode load_xml_profiles_file(const std::string& path) {
  static constexpr std::array<std::pair<const char*, const char*>, 6> kRenamed{{
      {"initialHeartbeatDelay", "initial_heartbeat_delay"},
      {"heartbeatPeriod", "heartbeat_period"},
      {"nackResponseDelay", "nack_response_delay"},
      {"nackSupressionDuration", "nack_supression_duration"},
      {"heartbeatResponseDelay", "heartbeat_response_delay"},
      {"initialAcknackDelay", "initial_acknack_delay"},
  }};
  std::ifstream in(path);
  if (!in) return eprosima::fastdds::dds::RETCODE_ERROR;
  std::string xml((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  for (const auto& [from, to] : kRenamed)
    for (const std::string prefix : {"<", "</"})
      for (std::size_t at = 0; (at = xml.find(prefix + from + ">", at)) != std::string::npos;)
        xml.replace(at, prefix.size() + std::char_traits<char>::length(from), prefix + to);
  // A discovery server is a <RemoteServer prefix=...> with a <metatrafficUnicastLocatorList> in
  // Fast DDS 2, its bare <locator> in Fast DDS 3 (which needs no prefix).
  static const std::regex kServerWrapper(R"(</?RemoteServer\b[^>]*>|</?metatrafficUnicastLocatorList>)");
  for (std::size_t begin = 0; (begin = xml.find("<discoveryServersList>", begin)) != std::string::npos;) {
    const std::size_t end = xml.find("</discoveryServersList>", begin);
    if (end == std::string::npos) break;
    const std::string list = std::regex_replace(xml.substr(begin, end - begin), kServerWrapper, "");
    xml.replace(begin, end - begin, list);
    begin += list.size();
  }
  return eprosima::fastdds::dds::DomainParticipantFactory::get_instance()->load_XML_profiles_string(
      xml.data(), xml.size());
}

/// Fast DDS 3 announces a type's TypeInformation whenever the type has a TypeObject, which content
/// filters need: there is nothing to turn off.
inline void announce_no_type_information(eprosima::fastdds::dds::TypeSupport& /*type*/) {}

/// The largest serialized sample, encapsulation included.
inline std::uint32_t max_serialized_size(const eprosima::fastdds::dds::TopicDataType& type) {
  return type.max_serialized_type_size;
}

/// Serializes `sample` as XCDR1 (the representation rsg's writers use) into `payload`.
inline bool serialize(eprosima::fastdds::dds::TopicDataType& type, const void* sample,
                      rtps::SerializedPayload_t& payload) {
  return type.serialize(sample, payload, eprosima::fastdds::dds::XCDR_DATA_REPRESENTATION);
}

/// Deserializes `payload` (either representation, as its encapsulation says) into `sample`.
inline bool deserialize(eprosima::fastdds::dds::TopicDataType& type, rtps::SerializedPayload_t& payload,
                        void* sample) {
  return type.deserialize(payload, sample);
}

/// Whether samples of `type` are plain in XCDR1 (loanable, data-sharing).
inline bool is_plain(const eprosima::fastdds::dds::TopicDataType& type) {
  return type.is_plain(eprosima::fastdds::dds::XCDR_DATA_REPRESENTATION);
}

/// Whether `type` has a key.
inline bool is_keyed(const eprosima::fastdds::dds::TopicDataType& type) {
  return type.is_compute_key_provided;
}

/// The locator of discovery server number `index` in `qos`, and the GUID prefix rsg gave it ("" on
/// Fast DDS 3, which finds servers by locator alone).
inline rtps::Locator_t discovery_server_locator(const eprosima::fastdds::dds::DomainParticipantQos& qos,
                                                std::size_t index) {
  return *(qos.wire_protocol().builtin.discovery_config.m_DiscoveryServers.begin() + index);
}
inline std::string discovery_server_prefix(const eprosima::fastdds::dds::DomainParticipantQos& /*qos*/,
                                           std::size_t /*index*/) {
  return "";
}

/// Delivers samples between endpoints of one process through the transports, as between processes.
/// Fast DDS 3 refuses the change once a participant is enabled (Fast DDS 2 applied it to the
/// participants created after it): call it before the first participant.
inline void disable_intraprocess_delivery() {
  auto* factory = eprosima::fastdds::dds::DomainParticipantFactory::get_instance();
  eprosima::fastdds::LibrarySettings settings;
  factory->get_library_settings(settings);
  if (settings.intraprocess_delivery == eprosima::fastdds::INTRAPROCESS_OFF) return;
  settings.intraprocess_delivery = eprosima::fastdds::INTRAPROCESS_OFF;
  if (factory->set_library_settings(settings) != kOk)
    throw std::logic_error("disable_intraprocess_delivery: called after a participant was enabled");
}

/// Has a reader of a plain type take its samples in place (a data-sharing sample as a loan of the
/// writer's memory), as Fast DDS 2 does, by listing XCDR1 as the representation it reads when its
/// profile lists none. Fast DDS 3 reads in place only a type that is plain in every representation
/// the reader accepts, and counts an empty list as both XCDR1 and XCDR2 there
/// (DataReaderImpl::get_payload_pool), although for matching an empty list means XCDR1 alone
/// (EDP::checkDataRepresentationQos): rsg's types are plain in XCDR1 only, so every sample was
/// deserialized into a copy, and DataReader::is_sample_valid(), which takes the sample for a loan
/// of the writer's memory and looks for the sequence number in front of it, judged every such copy
/// from a data-sharing writer overwritten (eProsima/Fast-DDS#2609): rsg_echo dropped them all. The
/// reader still matches the same writers.
inline void read_plain_samples_in_place(eprosima::fastdds::dds::DataReaderQos& qos) {
  auto& representations = qos.representation().m_value;
  if (representations.empty()) representations.push_back(eprosima::fastdds::dds::XCDR_DATA_REPRESENTATION);
}

/// Adds the discovery server number `id` at `locator` (Fast DDS 3 needs no server GUID prefix).
inline void add_discovery_server(eprosima::fastdds::dds::DomainParticipantQos& qos, unsigned /*id*/,
                                 const rtps::Locator_t& locator) {
  qos.wire_protocol().builtin.discovery_config.m_DiscoveryServers.push_back(locator);
}

#else  // Fast DDS 2.x

using DiscoveryProtocol = rtps::DiscoveryProtocol_t;

/// Fast DDS 2's DDS-SQL filter factory looks the TypeObject up by the topic's type name: registers
/// the type's objects under `name` too.
inline void rename_type(eprosima::fastdds::dds::TypeSupport& type, const std::string& name) {
  auto* factory = eprosima::fastrtps::types::TypeObjectFactory::get_instance();
  const std::string original = type.get_type_name();
  for (const bool complete : {true, false})
    if (const auto* object = factory->get_type_object(original, complete))
      factory->add_type_object(name, factory->get_type_identifier(original, complete), object);
  type->setName(name.c_str());
}

/// Cyclone DDS 0.10 drops the samples of writers that announce TypeInformation: Fast DDS 2 sends
/// none when told so.
inline void announce_no_type_information(eprosima::fastdds::dds::TypeSupport& type) {
  type->auto_fill_type_information(false);
  type->auto_fill_type_object(false);
}

inline std::uint32_t max_serialized_size(const eprosima::fastdds::dds::TopicDataType& type) {
  return type.m_typeSize;
}

inline bool serialize(eprosima::fastdds::dds::TopicDataType& type, const void* sample,
                      rtps::SerializedPayload_t& payload) {
  return type.serialize(const_cast<void*>(sample), &payload);
}

inline bool deserialize(eprosima::fastdds::dds::TopicDataType& type, rtps::SerializedPayload_t& payload,
                        void* sample) {
  return type.deserialize(&payload, sample);
}

inline bool is_plain(const eprosima::fastdds::dds::TopicDataType& type) { return type.is_plain(); }

inline ReturnCode load_xml_profiles_file(const std::string& path) {
  return eprosima::fastdds::dds::DomainParticipantFactory::get_instance()->load_XML_profiles_file(path);
}

inline bool is_keyed(const eprosima::fastdds::dds::TopicDataType& type) { return type.m_isGetKeyDefined; }

inline rtps::Locator_t discovery_server_locator(const eprosima::fastdds::dds::DomainParticipantQos& qos,
                                                std::size_t index) {
  auto server = qos.wire_protocol().builtin.discovery_config.m_DiscoveryServers.begin();
  std::advance(server, index);
  return *server->metatrafficUnicastLocatorList.begin();
}
inline std::string discovery_server_prefix(const eprosima::fastdds::dds::DomainParticipantQos& qos,
                                           std::size_t index) {
  auto server = qos.wire_protocol().builtin.discovery_config.m_DiscoveryServers.begin();
  std::advance(server, index);
  std::ostringstream text;
  text << server->guidPrefix;
  return text.str();
}

inline void disable_intraprocess_delivery() {
  eprosima::fastrtps::LibrarySettingsAttributes settings;
  settings.intraprocess_delivery = eprosima::fastrtps::INTRAPROCESS_OFF;
  eprosima::fastrtps::xmlparser::XMLProfileManager::library_settings(settings);
}

/// Fast DDS 2.9 reads a plain type in place whatever the reader's representations. 2.14 (since
/// eProsima/Fast-DDS#4681, in a 2.14 patch release) does what 3.x does (see the 3.x version above):
/// an empty list counts as XCDR1 and XCDR2 there, so the reader lists XCDR1, where 2.x keeps a
/// reader's representations (type_consistency()), which matches the same writers
/// (EDP::checkDataRepresentationQos).
inline void read_plain_samples_in_place(eprosima::fastdds::dds::DataReaderQos& qos) {
#if FASTRTPS_VERSION_MINOR >= 14
  auto& representations = qos.type_consistency().representation.m_value;
  if (representations.empty()) representations.push_back(eprosima::fastdds::dds::XCDR_DATA_REPRESENTATION);
#else
  (void)qos;
#endif
}

/// Fast DDS 2 finds server number `id` by its default GUID prefix.
inline void add_discovery_server(eprosima::fastdds::dds::DomainParticipantQos& qos, unsigned id,
                                 const rtps::Locator_t& locator) {
  eprosima::fastdds::rtps::RemoteServerAttributes remote;
  eprosima::fastdds::rtps::get_server_client_default_guidPrefix(static_cast<int>(id), remote.guidPrefix);
  remote.metatrafficUnicastLocatorList.push_back(locator);
  qos.wire_protocol().builtin.discovery_config.m_DiscoveryServers.push_back(remote);
}

#endif

}  // namespace rsg::dds::internal
