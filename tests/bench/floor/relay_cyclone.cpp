// rsg_bench_relay_cyclone DOMAIN TOPIC: the leanest relay (relay_loop.hpp) on Cyclone DDS's C
// API, with Cyclone's default writer QoS (reliable, volatile, keep last 1).
#include <cstring>
#include <iostream>
#include <string>

#include "tests/bench/floor/cyclone_topic.hpp"
#include "tests/bench/floor/relay_loop.hpp"

int main(int argc, char** argv) {
  if (argc != 3) {
    std::cerr << "usage: rsg_bench_relay_cyclone DOMAIN TOPIC\n";
    return 2;
  }
  using rsg::interop::Entity;
  try {
    const rsg::bench::CycloneTopic dds(argv[1], argv[2]);
    Entity writer(dds_create_writer(dds.participant.get(), dds.topic.get(), nullptr, nullptr), "writer");
    rsg_RobotState sample{};
    rsg::bench::relay_frames(
        [&](const rsg::bench::StampBytes& stamp) {
          std::memcpy(sample.elbow_d, stamp.elbow_d, sizeof sample.elbow_d);
          std::memcpy(&sample.time, stamp.time, sizeof sample.time);
          dds_write(writer.get(), &sample);
        },
        [&] {
          dds_publication_matched_status_t status{};
          return dds_get_publication_matched_status(writer.get(), &status) == DDS_RETCODE_OK &&
                 status.current_count > 0;
        });
    return 0;
  } catch (const std::exception& error) {
    std::cerr << "rsg_bench_relay_cyclone: " << error.what() << '\n';
    return 1;
  }
}
