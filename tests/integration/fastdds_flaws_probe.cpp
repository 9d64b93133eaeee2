// rsg_fastdds_flaws_probe: a plain Fast DDS participant, as any application on the robot's network
// would make one, with none of rsg's defences: not rsg::dds::Participant (no transport guard, no
// RTPS screen, no discovery bounds), no rsg profile loaded. Test helper, not a product
// (test_fastdds_flaws.py, test_check_config.py): the control that shows what a published Fast DDS
// flaw does to the Fast DDS this build links.
//
// It makes a DomainParticipant straight from DomainParticipantFactory (Fast DDS's defaults, or the
// participant profile --participant-profile of the XML file --profiles, loaded by Fast DDS itself
// with no check of rsg's) and a reader of rsg::RobotState on --topic (Fast DDS's default reader
// QoS), then says on stdout, one line each, flushed:
//   "fastdds X.Y.Z"           the version of the Fast DDS library it was built with, first
//   "participant created"     once create_participant returned (a profile Fast DDS loops on never
//                             gets there)
//   "reader created"          once the reader exists
//   "matched N"               each time the number of matched writers changes
//   "samples N"               every 200 ms, the samples taken so far
// and runs until --duration seconds have passed (then exits 0) or it is killed.
// Exit status: 0, or 2 when the profile does not load or an entity cannot be created.
#include <RobotState.h>
#include <RobotStatePubSubTypes.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <fastdds/dds/core/status/SubscriptionMatchedStatus.hpp>
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/log/Log.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/subscriber/qos/DataReaderQos.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>
#include <string>
#include <thread>

#include "rsg/dds/fastdds.hpp"

namespace {
namespace fdds = eprosima::fastdds::dds;

void say(const std::string& line) {
  std::printf("%s\n", line.c_str());
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
  int domain = 0;
  std::string topic_name = "robot_state";
  std::string profiles;
  std::string participant_profile;
  double duration_s = 60;
  bool warnings = false;
  CLI::App app("A plain Fast DDS participant with a RobotState reader, none of rsg's defences",
               "rsg_fastdds_flaws_probe");
  app.add_option("--domain", domain);
  app.add_option("--topic", topic_name);
  app.add_option("--profiles", profiles, "An XML profile file, loaded by Fast DDS itself");
  app.add_option("--participant-profile", participant_profile, "A participant profile of --profiles");
  app.add_option("--duration", duration_s, "Seconds to run");
  app.add_flag("--warnings", warnings, "Fast DDS's warnings too (its default: errors only)");
  CLI11_PARSE(app, argc, argv);

#if RSG_FASTDDS_MAJOR >= 3
  say(std::string("fastdds ") + FASTDDS_VERSION_STR);
#else
  say(std::string("fastdds ") + FASTRTPS_VERSION_STR);
#endif
  if (warnings) fdds::Log::SetVerbosity(fdds::Log::Kind::Warning);
  auto* factory = fdds::DomainParticipantFactory::get_instance();
  if (!profiles.empty() && factory->load_XML_profiles_file(profiles) != rsg::dds::kOk) {
    say("Fast DDS did not load " + profiles);
    return 2;
  }
  fdds::DomainParticipant* participant =
      participant_profile.empty()
          ? factory->create_participant(domain, factory->get_default_participant_qos())
          : factory->create_participant_with_profile(domain, participant_profile);
  if (participant == nullptr) {
    say("no participant");
    return 2;
  }
  say("participant created");

  fdds::TypeSupport type(new rsg::RobotStatePubSubType());
  if (type.register_type(participant) != rsg::dds::kOk) return 2;
  fdds::Topic* topic = participant->create_topic(topic_name, type.get_type_name(), fdds::TOPIC_QOS_DEFAULT);
  fdds::Subscriber* subscriber =
      topic ? participant->create_subscriber(fdds::SUBSCRIBER_QOS_DEFAULT) : nullptr;
  fdds::DataReader* reader =
      subscriber ? subscriber->create_datareader(topic, fdds::DATAREADER_QOS_DEFAULT) : nullptr;
  if (reader == nullptr) {
    say("no reader");
    return 2;
  }
  say("reader created");

  rsg::RobotState sample;
  fdds::SampleInfo info;
  unsigned long long samples = 0;
  int matched = 0;
  const auto start = std::chrono::steady_clock::now();
  auto next_report = start;
  while (std::chrono::steady_clock::now() - start < std::chrono::duration<double>(duration_s)) {
    while (reader->take_next_sample(&sample, &info) == rsg::dds::kOk)
      if (info.valid_data) ++samples;
    fdds::SubscriptionMatchedStatus status;
    if (reader->get_subscription_matched_status(status) == rsg::dds::kOk && status.current_count != matched) {
      matched = status.current_count;
      say("matched " + std::to_string(matched));
    }
    if (std::chrono::steady_clock::now() >= next_report) {
      say("samples " + std::to_string(samples));
      next_report += std::chrono::milliseconds(200);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  participant->delete_contained_entities();
  factory->delete_participant(participant);
  return 0;
}
