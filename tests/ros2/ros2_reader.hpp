// A Cyclone DDS reader as a ROS 2 subscription is one (volatile), for the tests' echo programs.
#pragma once

#include <dds/dds.h>

#include <iostream>
#include <string>

#include "tests/interop/cyclone_robot_state.hpp"  // Entity, Qos

namespace rsg::ros2_test {

class VolatileReader {
 public:
  /// `qos` gives reliability and history; durability is made volatile, as ROS 2's presets have it.
  VolatileReader(dds_domainid_t domain, const dds_topic_descriptor_t* type, const std::string& topic_name,
                 interop::Qos& qos)
      : topic_name_(topic_name),
        participant_(dds_create_participant(domain, nullptr, nullptr), "participant"),
        topic_(dds_create_topic(participant_.get(), type, topic_name.c_str(), nullptr, nullptr), "topic"),
        reader_(dds_create_reader(participant_.get(), topic_.get(), made_volatile(qos), nullptr), "reader"),
        waitset_(dds_create_waitset(participant_.get()), "waitset") {
    dds_waitset_attach(waitset_.get(), reader_.get(), 0);
  }

  /// Waits up to `timeout` for a writer. A volatile reader gets what is written after *it* knows
  /// the writer (the writer may know the reader earlier), so this prints "matched" to stderr for a
  /// test to start the stream only then. Afterwards the waitset wakes on data.
  bool wait_for_writer(dds_duration_t timeout, const char* program) {
    dds_set_status_mask(reader_.get(), DDS_SUBSCRIPTION_MATCHED_STATUS);
    dds_subscription_matched_status_t matched{};
    while (dds_get_subscription_matched_status(reader_.get(), &matched) == DDS_RETCODE_OK &&
           matched.current_count == 0)
      if (dds_waitset_wait(waitset_.get(), nullptr, 0, timeout) == 0) {
        std::cerr << program << ": no writer on " << topic_name_ << '\n';
        return false;
      }
    std::cerr << "matched" << std::endl;
    dds_set_status_mask(reader_.get(), DDS_DATA_AVAILABLE_STATUS);
    return true;
  }

  dds_entity_t reader() const { return reader_.get(); }
  dds_entity_t waitset() const { return waitset_.get(); }

 private:
  static const dds_qos_t* made_volatile(interop::Qos& qos) {
    dds_qset_durability(qos.get(), DDS_DURABILITY_VOLATILE);
    return qos.get();
  }

  std::string topic_name_;
  interop::Entity participant_;
  interop::Entity topic_;
  interop::Entity reader_;
  interop::Entity waitset_;
};

}  // namespace rsg::ros2_test
