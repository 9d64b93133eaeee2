// Test publisher for the multi-process view test: waits for the given number of readers, then
// publishes the mixed-selection stream (every subset of groups, in turn) at a fixed rate, records
// each sample as canonical JSON, and waits until every reader has acknowledged everything.
//
//   rsg_views_publish --domain N --topic NAME [--partition P] --readers K --count N --record FILE
//                     [--wait-for-go]
#include <RobotState.h>

#include <CLI/CLI.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/qos/DataWriterQos.hpp>
#include <fstream>
#include <iostream>
#include <string>
#include <thread>

#include "rsg/dds/participant.hpp"
#include "rsg/dds/profiles.hpp"
#include "rsg/dds/robot_state.hpp"
#include "rsg/wire/json.hpp"
#include "tests/dds/mixed_stream.hpp"

namespace fdds = eprosima::fastdds::dds;

int main(int argc, char** argv) {
  int domain = 0;
  std::string topic_name = "robot_state";
  std::vector<std::string> partitions;
  int readers = 1;
  std::size_t count = 256;
  double rate_hz = 1000;
  std::string record;
  bool wait_for_go = false;
  CLI::App app{"Publishes the mixed-selection RobotState test stream.", "rsg_views_publish"};
  app.add_option("--domain", domain);
  app.add_option("--topic", topic_name);
  app.add_option("--partition", partitions);
  app.add_option("--readers", readers, "Readers to wait for before publishing");
  app.add_option("--count", count);
  app.add_option("--rate", rate_hz)->check(CLI::PositiveNumber);
  app.add_option("--record", record, "Canonical JSON of each published sample, one per line")->required();
  app.add_flag("--wait-for-go", wait_for_go,
               "Once the readers matched, publish only after a line arrives on stdin: the test's go once "
               "each reader says it matched this writer too");
  CLI11_PARSE(app, argc, argv);

  rsg::dds::load_profiles(rsg::dds::default_profiles_dir());
  rsg::dds::Participant participant(domain, "rsg_participant");
  fdds::Publisher& publisher = *participant.publisher(partitions);
  fdds::DataWriterQos qos = publisher.get_default_datawriter_qos();
  qos.reliability().kind = fdds::RELIABLE_RELIABILITY_QOS;
  qos.history().kind = fdds::KEEP_ALL_HISTORY_QOS;
  // It starts once it has matched its readers, but a reader may match it later (discovery is not
  // symmetric): a transient-local reader then still gets the whole stream from the history.
  qos.durability().kind = fdds::TRANSIENT_LOCAL_DURABILITY_QOS;
  qos.deadline().period = rsg::dds::Duration(0, 100'000'000);  // like the gateway's
  fdds::DataWriter* writer = publisher.create_datawriter(participant.robot_state_topic(topic_name), qos);
  if (writer == nullptr || !rsg::test::wait_for_matched_readers(*writer, readers)) {
    std::cerr << "rsg_views_publish: the readers did not match\n";
    return 1;
  }
  if (wait_for_go) {
    std::string go;
    std::getline(std::cin, go);
  }

  std::ofstream out(record);
  const auto period = std::chrono::duration_cast<std::chrono::steady_clock::duration>(
      std::chrono::duration<double>(1.0 / rate_hz));
  auto next = std::chrono::steady_clock::now();
  rsg::RobotState sample;
  for (const rsg::wire::StateValues& values : rsg::test::mixed_stream(count)) {
    rsg::dds::to_sample(values, sample);
    if (!rsg::dds::succeeded(writer->write(&sample))) {
      std::cerr << "rsg_views_publish: write failed\n";
      return 1;
    }
    out << rsg::wire::to_canonical_json(values) << '\n';
    std::this_thread::sleep_until(next += period);
  }
  out.close();
  if (writer->wait_for_acknowledgments(rsg::dds::Duration(60, 0)) != rsg::dds::kOk) {
    std::cerr << "rsg_views_publish: not every reader acknowledged the stream\n";
    return 1;
  }
  return 0;
}
