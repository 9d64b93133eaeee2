#include "rsg/participant.hpp"

#include <RobotStatePubSubTypes.h>
#include <RobotStateTypeObject.h>

#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <stdexcept>

namespace rsg {

Participant::Participant(int domain, const std::string& profile) {
  auto* factory = fdds::DomainParticipantFactory::get_instance();
  participant_ = profile.empty() ? factory->create_participant(domain, fdds::PARTICIPANT_QOS_DEFAULT)
                                 : factory->create_participant_with_profile(domain, profile);
  if (!participant_)
    throw std::runtime_error("cannot create DDS participant on domain " + std::to_string(domain) +
                             " with profile '" + profile + "' (are the XML profiles loaded?)");
}

Participant::Participant(int domain, const fdds::DomainParticipantQos& qos) {
  participant_ = fdds::DomainParticipantFactory::get_instance()->create_participant(domain, qos);
  if (!participant_)
    throw std::runtime_error("cannot create DDS participant on domain " + std::to_string(domain));
}

Participant::~Participant() {
  participant_->delete_contained_entities();
  fdds::DomainParticipantFactory::get_instance()->delete_participant(participant_);
}

fdds::Topic* Participant::topic(const std::string& name, fdds::TypeSupport type) {
  if (auto* existing = participant_->find_topic(name, eprosima::fastrtps::Duration_t(0, 0))) return existing;
  type->auto_fill_type_information(false);
  type->auto_fill_type_object(false);
  if (participant_->register_type(type) != ReturnCode_t::RETCODE_OK)
    throw std::runtime_error("cannot register type " + type.get_type_name());
  fdds::Topic* created = participant_->create_topic(name, type.get_type_name(), fdds::TOPIC_QOS_DEFAULT);
  if (!created) throw std::runtime_error("cannot create topic '" + name + "'");
  return created;
}

fdds::Topic* Participant::robot_state_topic(const std::string& name) {
  registerRobotStateTypes();  // the type object the DDS-SQL filter factory looks members up in
  return topic(name, fdds::TypeSupport(new RobotStatePubSubType()));
}

fdds::Publisher* Participant::publisher(const std::vector<std::string>& partitions) {
  fdds::PublisherQos qos = participant_->get_default_publisher_qos();
  for (const auto& partition : partitions) qos.partition().push_back(partition.c_str());
  fdds::Publisher* created = participant_->create_publisher(qos);
  if (!created) throw std::runtime_error("cannot create DDS publisher");
  return created;
}

fdds::Subscriber* Participant::subscriber(const std::vector<std::string>& partitions) {
  fdds::SubscriberQos qos = participant_->get_default_subscriber_qos();
  for (const auto& partition : partitions) qos.partition().push_back(partition.c_str());
  fdds::Subscriber* created = participant_->create_subscriber(qos);
  if (!created) throw std::runtime_error("cannot create DDS subscriber");
  return created;
}

}  // namespace rsg
