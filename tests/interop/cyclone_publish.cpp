// Cyclone DDS publisher (C API, idlc-generated C type) of RobotState samples read from canonical
// JSON lines: waits for READERS matched readers, writes every line, waits for acknowledgements.
//
//   rsg_cyclone_publish DOMAIN TOPIC PARTITION READERS FILE   (exit 0 when all were acknowledged)
#include <fstream>
#include <iostream>
#include <string>
#include <thread>

#include "rsg/wire/json.hpp"
#include "tests/interop/cyclone_robot_state.hpp"

int main(int argc, char** argv) {
  if (argc != 6) {
    std::cerr << "usage: rsg_cyclone_publish DOMAIN TOPIC PARTITION READERS FILE\n";
    return 2;
  }
  const auto domain = static_cast<dds_domainid_t>(std::stoul(argv[1]));
  const std::string topic_name = argv[2];
  const char* partition = argv[3];
  const auto readers = static_cast<uint32_t>(std::stoul(argv[4]));
  std::ifstream input(argv[5]);
  if (!input) {
    std::cerr << "rsg_cyclone_publish: cannot open " << argv[5] << '\n';
    return 2;
  }
  using rsg::interop::Entity;
  using rsg::interop::Qos;
  try {
    Entity participant(dds_create_participant(domain, nullptr, nullptr), "participant");
    Entity topic(
        dds_create_topic(participant.get(), &rsg_RobotState_desc, topic_name.c_str(), nullptr, nullptr),
        "topic");
    Qos publisher_qos;
    dds_qset_partition1(publisher_qos.get(), partition);
    Entity publisher(dds_create_publisher(participant.get(), publisher_qos.get(), nullptr), "publisher");
    Qos writer_qos;
    dds_qset_reliability(writer_qos.get(), DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
    dds_qset_history(writer_qos.get(), DDS_HISTORY_KEEP_ALL, 0);
    // Fast DDS 2.9 reads XCDR1 only; say so rather than rely on Cyclone's choice for final types.
    const dds_data_representation_id_t xcdr1[] = {DDS_DATA_REPRESENTATION_XCDR1};
    dds_qset_data_representation(writer_qos.get(), 1, xcdr1);
    Entity writer(dds_create_writer(publisher.get(), topic.get(), writer_qos.get(), nullptr), "writer");

    dds_publication_matched_status_t matched{};
    for (int waits = 0; waits < 600 && matched.current_count < readers; ++waits) {  // a minute at most
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
      dds_get_publication_matched_status(writer.get(), &matched);
    }
    if (matched.current_count != readers) {
      std::cerr << "rsg_cyclone_publish: " << matched.current_count << " of " << readers
                << " readers matched\n";
      return 1;
    }

    rsg_RobotState sample;
    std::string line;
    while (std::getline(input, line)) {
      const rsg::wire::Parsed<rsg::wire::StateValues> values = rsg::wire::parse_canonical_json(line);
      if (!values) {
        std::cerr << "rsg_cyclone_publish: " << values.error() << '\n';
        return 2;
      }
      rsg::interop::to_sample(*values, sample);
      if (const dds_return_t rc = dds_write(writer.get(), &sample); rc != DDS_RETCODE_OK) {
        std::cerr << "rsg_cyclone_publish: dds_write: " << dds_strretcode(rc) << '\n';
        return 1;
      }
    }
    if (dds_wait_for_acks(writer.get(), DDS_SECS(60)) != DDS_RETCODE_OK) {
      std::cerr << "rsg_cyclone_publish: not every reader acknowledged\n";
      return 1;
    }
    return 0;
  } catch (const std::exception& error) {
    std::cerr << "rsg_cyclone_publish: " << error.what() << '\n';
    return 1;
  }
}
