// rsg_status_probe: prints every GatewayStatus sample as one JSON line (the --stats-file form),
// so that integration tests can check what the status topic says. Test helper, not a product.
#include <GatewayStatusPubSubTypes.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <fastdds/dds/core/condition/WaitSet.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <iostream>

#include "rsg/dds/fastdds.hpp"
#include "rsg/dds/participant.hpp"
#include "rsg/dds/profiles.hpp"
#include "status/status_sample.hpp"

int main(int argc, char** argv) {
  int domain = 0;
  std::string topic_name = "rsg_gateway_status";
  std::string partition;
  double timeout_s = 30;
  CLI::App app("Prints GatewayStatus samples as JSON lines until --timeout", "rsg_status_probe");
  app.add_option("--domain", domain);
  app.add_option("--topic", topic_name);
  app.add_option("--partition", partition);
  app.add_option("--timeout", timeout_s, "Seconds to run");
  CLI11_PARSE(app, argc, argv);

  namespace fdds = eprosima::fastdds::dds;
  rsg::dds::load_profiles(rsg::dds::default_profiles_dir());
  rsg::dds::Participant participant(domain, "rsg_participant");
  fdds::Topic* topic = participant.topic(topic_name, fdds::TypeSupport(new rsg::GatewayStatusPubSubType()));
  fdds::Subscriber* subscriber = participant.subscriber(
      partition.empty() ? std::vector<std::string>{} : std::vector<std::string>{partition});
  fdds::DataReader* reader = subscriber->create_datareader_with_profile(topic, "rsg_status_reader");
  if (!reader) return 2;

  fdds::WaitSet waitset;
  reader->get_statuscondition().set_enabled_statuses(fdds::StatusMask::data_available());
  waitset.attach_condition(reader->get_statuscondition());
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  rsg::GatewayStatus sample;
  fdds::SampleInfo info;
  fdds::ConditionSeq triggered;
  while (std::chrono::steady_clock::now() < deadline) {
    waitset.wait(triggered, rsg::dds::Duration(0, 200'000'000));
    while (reader->take_next_sample(&sample, &info) == rsg::dds::kOk)
      if (info.valid_data)
        std::cout << rsg::status::to_json(rsg::status::from_status_sample(sample)) << std::endl;
  }
  waitset.detach_condition(reader->get_statuscondition());
  return 0;
}
