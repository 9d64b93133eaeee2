// Cyclone DDS subscriber (C API, idlc-generated C type) of rsg's RobotState topic: prints each
// sample as rsg's canonical JSON, so that a test compares it with what the rsg side published.
//
//   rsg_cyclone_echo DOMAIN TOPIC PARTITION COUNT TIMEOUT_S   (exit 0 after COUNT samples, 1 on timeout)
#include <cstdio>
#include <iostream>
#include <string>

#include "rsg/wire/json.hpp"
#include "tests/interop/cyclone_robot_state.hpp"

int main(int argc, char** argv) {
  if (argc != 6) {
    std::cerr << "usage: rsg_cyclone_echo DOMAIN TOPIC PARTITION COUNT TIMEOUT_S\n";
    return 2;
  }
  const auto domain = static_cast<dds_domainid_t>(std::stoul(argv[1]));
  const std::string topic_name = argv[2];
  const char* partition = argv[3];
  const unsigned long count = std::stoul(argv[4]);
  const dds_duration_t timeout = DDS_SECS(std::stol(argv[5]));
  using rsg::interop::Entity;
  using rsg::interop::Qos;
  try {
    Entity participant(dds_create_participant(domain, nullptr, nullptr), "participant");
    Entity topic(
        dds_create_topic(participant.get(), &rsg_RobotState_desc, topic_name.c_str(), nullptr, nullptr),
        "topic");
    Qos subscriber_qos;
    dds_qset_partition1(subscriber_qos.get(), partition);
    Entity subscriber(dds_create_subscriber(participant.get(), subscriber_qos.get(), nullptr), "subscriber");
    Qos reader_qos;  // every sample: reliable, all history
    dds_qset_reliability(reader_qos.get(), DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
    dds_qset_history(reader_qos.get(), DDS_HISTORY_KEEP_ALL, 0);
    // Discovery is not symmetric: the test's publisher starts once it has matched this reader,
    // which may learn of the writer later. Transient-local, it still gets what was sent before.
    dds_qset_durability(reader_qos.get(), DDS_DURABILITY_TRANSIENT_LOCAL);
    Entity reader(dds_create_reader(subscriber.get(), topic.get(), reader_qos.get(), nullptr), "reader");
    dds_set_status_mask(reader.get(), DDS_DATA_AVAILABLE_STATUS);
    Entity waitset(dds_create_waitset(participant.get()), "waitset");
    dds_waitset_attach(waitset.get(), reader.get(), 0);

    rsg::wire::StateValues values;
    const bool complete = rsg::interop::print_samples<rsg_RobotState>(
        reader.get(), waitset.get(), count, timeout, "rsg_cyclone_echo", [&](const rsg_RobotState& sample) {
          rsg::interop::to_values(sample, values);
          return rsg::wire::to_canonical_json(values);
        });
    if (!complete) return 1;
    return 0;
  } catch (const std::exception& error) {
    std::cerr << "rsg_cyclone_echo: " << error.what() << '\n';
    return 1;
  }
}
