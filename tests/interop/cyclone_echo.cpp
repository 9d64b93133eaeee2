// Cyclone DDS subscriber (C API, idlc-generated C type) of rsg's RobotState topic: prints each
// sample as rsg's canonical JSON, so that a test compares it with what the rsg side published.
//
//   rsg_cyclone_echo DOMAIN TOPIC PARTITION COUNT TIMEOUT_S   (exit 0 after COUNT samples, 1 on timeout)
#include <cstdio>
#include <iostream>
#include <string>

#include "cyclone_robot_state.hpp"
#include "rsg/json.hpp"

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
    Entity reader(dds_create_reader(subscriber.get(), topic.get(), reader_qos.get(), nullptr), "reader");
    dds_set_status_mask(reader.get(), DDS_DATA_AVAILABLE_STATUS);
    Entity waitset(dds_create_waitset(participant.get()), "waitset");
    dds_waitset_attach(waitset.get(), reader.get(), 0);

    unsigned long received = 0;
    rsg::StateValues values;
    std::string line;
    while (received < count) {
      if (dds_waitset_wait(waitset.get(), nullptr, 0, timeout) == 0) {
        std::cerr << "rsg_cyclone_echo: timeout after " << received << " samples\n";
        return 1;
      }
      // Take until the reader is empty: DATA_AVAILABLE is reset by the first take, not re-raised
      // for what a full buffer left behind.
      while (received < count) {
        void* samples[64] = {};  // null: Cyclone loans its own buffers
        dds_sample_info_t infos[64];
        const dds_return_t taken = dds_take(reader.get(), samples, infos, 64, 64);
        if (taken <= 0) break;
        for (dds_return_t i = 0; i < taken && received < count; ++i) {
          if (!infos[i].valid_data) continue;
          rsg::interop::to_values(*static_cast<const rsg_RobotState*>(samples[i]), values);
          line = rsg::to_canonical_json(values);
          line += '\n';
          std::fwrite(line.data(), 1, line.size(), stdout);
          ++received;
        }
        dds_return_loan(reader.get(), samples, taken);
      }
      std::fflush(stdout);
    }
    return 0;
  } catch (const std::exception& error) {
    std::cerr << "rsg_cyclone_echo: " << error.what() << '\n';
    return 1;
  }
}
