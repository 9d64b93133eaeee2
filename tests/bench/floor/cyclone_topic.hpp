// The floor's Cyclone DDS processes: a participant on a domain and the RobotState topic in it.
#pragma once

#include <string>

#include "tests/interop/cyclone_robot_state.hpp"

namespace rsg::bench {

struct CycloneTopic {
  CycloneTopic(const std::string& domain, const char* name)
      : participant(dds_create_participant(static_cast<dds_domainid_t>(std::stoul(domain)), nullptr, nullptr),
                    "participant"),
        topic(dds_create_topic(participant.get(), &rsg_RobotState_desc, name, nullptr, nullptr), "topic") {}

  interop::Entity participant;  // first: outlives the topic
  interop::Entity topic;
};

}  // namespace rsg::bench
