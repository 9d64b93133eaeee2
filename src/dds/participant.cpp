#include "rsg/dds/participant.hpp"

#include <RobotStatePubSubTypes.h>
#include <RobotStateTypeObject.h>

#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <stdexcept>

#include "dds/internal/fastdds_compat.hpp"
#include "dds/internal/rtps_guard.hpp"
#include "rsg/error.hpp"

namespace rsg::dds {
namespace fdds = eprosima::fastdds::dds;

namespace {

fdds::DomainParticipantQos profile_qos(const std::string& profile) {
  fdds::DomainParticipantQos qos;
  auto* factory = fdds::DomainParticipantFactory::get_instance();
  if (profile.empty()) return factory->get_default_participant_qos();
  if (factory->get_participant_qos_from_profile(profile, qos) != kOk)
    throw InputError("no participant profile named '" + profile + "' (are the XML profiles loaded?)");
  return qos;
}

fdds::DomainParticipantQos with_discovery(fdds::DomainParticipantQos qos, int domain,
                                          const DiscoveryOptions& discovery) {
  apply_discovery(discovery, domain, qos);
  return qos;
}

}  // namespace

Participant::Participant(int domain, const std::string& profile)
    : Participant(domain, profile_qos(profile)) {}

Participant::Participant(int domain, const std::string& profile, const DiscoveryOptions& discovery,
                         fdds::DomainParticipantListener* listener)
    : Participant(domain, with_discovery(profile_qos(profile), domain, discovery), listener) {}

Participant::Participant(int domain, const fdds::DomainParticipantQos& qos,
                         fdds::DomainParticipantListener* listener) {
  fdds::DomainParticipantQos guarded = qos;
  internal::guard_transports(guarded, guard_);
  internal::bound_discovery(guarded);
  participant_ = fdds::DomainParticipantFactory::get_instance()->create_participant(domain, guarded, listener,
                                                                                    fdds::StatusMask::none());
  if (!participant_)
    throw EnvironmentError("cannot create DDS participant on domain " + std::to_string(domain));
}

Participant::~Participant() {
  participant_->delete_contained_entities();
  fdds::DomainParticipantFactory::get_instance()->delete_participant(participant_);
}

fdds::Topic* Participant::topic(const std::string& name, fdds::TypeSupport type) {
  if (auto* existing = participant_->find_topic(name, Duration(0, 0))) return existing;
  internal::announce_no_type_information(type);
  if (participant_->register_type(type) != kOk)
    throw EnvironmentError("cannot register type " + type.get_type_name());
  fdds::Topic* created = participant_->create_topic(name, type.get_type_name(), fdds::TOPIC_QOS_DEFAULT);
  if (!created) throw EnvironmentError("cannot create topic '" + name + "'");
  return created;
}

fdds::Topic* Participant::robot_state_topic(const std::string& name, const std::string& type_name) {
  registerRobotStateTypes();  // the type object the DDS-SQL filter factory looks members up in
  fdds::TypeSupport type(new RobotStatePubSubType());
  if (!type_name.empty()) {
    dds::internal::rename_type(type, type_name);  // where the filter factory still finds its type object
  }
  return topic(name, type);
}

fdds::Publisher* Participant::publisher(const std::vector<std::string>& partitions) {
  fdds::PublisherQos qos = participant_->get_default_publisher_qos();
  for (const auto& partition : partitions) qos.partition().push_back(partition.c_str());
  fdds::Publisher* created = participant_->create_publisher(qos);
  if (!created) throw EnvironmentError("cannot create DDS publisher");
  return created;
}

fdds::Subscriber* Participant::subscriber(const std::vector<std::string>& partitions) {
  fdds::SubscriberQos qos = participant_->get_default_subscriber_qos();
  for (const auto& partition : partitions) qos.partition().push_back(partition.c_str());
  fdds::Subscriber* created = participant_->create_subscriber(qos);
  if (!created) throw EnvironmentError("cannot create DDS subscriber");
  return created;
}

}  // namespace rsg::dds
