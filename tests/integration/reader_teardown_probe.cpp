// rsg_reader_teardown_probe: deletes a reader that a writer's samples are waiting for, and says
// whether the delete returned. Test helper, not a product (test_reader_teardown.py).
//
// The reader (RobotState on --topic, with the QoS of the XML reader profile --profile) keeps at
// most 4 samples and never takes them (KEEP_ALL, 4 at most, whatever the profile says), so Fast
// DDS refuses the writer's next payload. Seen on 2.9.1, 2.14.5 and 3.1.2 with data-sharing on: the
// delete then joins the reader's data-sharing listener thread, which spins and never returns
// (eProsima/Fast-DDS#6490, in no release yet); without data-sharing the delete returns at once.
// --data-sharing on forces data-sharing on whatever the profile says: the control.
// Exit status: 0 the delete returned, 3 it had not returned after --wait seconds (the process ends
// without it), 2 no writer matched or the reader never filled. It prints "matched" once its reader
// has matched a writer.
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <fastdds/dds/core/status/SubscriptionMatchedStatus.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/qos/DataReaderQos.hpp>
#include <future>
#include <thread>

#include "rsg/dds/fastdds.hpp"
#include "rsg/dds/participant.hpp"
#include "rsg/dds/profiles.hpp"
#include "rsg/dds/views.hpp"  // load_reader_qos

namespace {
namespace fdds = eprosima::fastdds::dds;
using Seconds = std::chrono::duration<double>;

constexpr int kHistory = 4;

// Waits until `done` or `limit` has passed; false on the limit.
template <typename Done>
bool wait_until(Done done, Seconds limit) {
  const auto start = std::chrono::steady_clock::now();
  while (!done()) {
    if (std::chrono::steady_clock::now() - start > limit) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  int domain = 0;
  std::string topic_name = "robot_state";
  std::string profile = "rsg_state_reader";
  std::string data_sharing = "as-profiled";
  double wait_s = 10;
  CLI::App app("Deletes a reader whose writer's payloads it refuses; says whether that returned",
               "rsg_reader_teardown_probe");
  app.add_option("--domain", domain);
  app.add_option("--topic", topic_name);
  app.add_option("--profile", profile, "XML data reader profile");
  app.add_option("--data-sharing", data_sharing)->check(CLI::IsMember({"as-profiled", "on"}));
  app.add_option("--wait", wait_s, "Seconds the delete may take");
  CLI11_PARSE(app, argc, argv);

  rsg::dds::load_profiles(rsg::dds::default_profiles_dir());
  rsg::dds::Participant participant(domain, "rsg_participant");
  fdds::Topic* topic = participant.robot_state_topic(topic_name);
  fdds::Subscriber* subscriber = participant.subscriber();
  fdds::DataReaderQos qos = rsg::dds::load_reader_qos(*subscriber, profile);
  qos.history().kind = fdds::KEEP_ALL_HISTORY_QOS;
  qos.resource_limits().max_samples = kHistory;
  qos.resource_limits().max_instances = 1;
  qos.resource_limits().max_samples_per_instance = kHistory;
  qos.resource_limits().allocated_samples = kHistory;
  if (data_sharing == "on") qos.data_sharing().automatic();
  fdds::DataReader* reader = subscriber->create_datareader(topic, qos);
  if (reader == nullptr) return 2;

  // Matched first, then filled: the test starts the writer's stream once "matched" is out.
  fdds::SubscriptionMatchedStatus matched;
  if (!wait_until(
          [&] {
            return reader->get_subscription_matched_status(matched) == rsg::dds::kOk &&
                   matched.current_count >= 1;
          },
          Seconds(30))) {
    std::printf("no writer of '%s' matched in 30 s\n", topic_name.c_str());
    return 2;
  }
  std::printf("matched\n");
  std::fflush(stdout);
  if (!wait_until([&] { return reader->get_unread_count() >= kHistory; }, Seconds(30))) {
    std::printf("the reader got %llu samples in 30 s, not %d\n",
                static_cast<unsigned long long>(reader->get_unread_count()), kHistory);
    return 2;
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(300));  // the writer's next payloads wait
  std::printf("the reader's history is full (%d samples); deleting it\n", kHistory);
  std::fflush(stdout);

  const auto deleting = std::chrono::steady_clock::now();
  std::promise<void> deleted;
  std::thread deleter([&] {
    subscriber->delete_datareader(reader);
    deleted.set_value();
  });
  if (deleted.get_future().wait_for(Seconds(wait_s)) == std::future_status::timeout) {
    std::printf("hung: the delete had not returned after %.0f s\n", wait_s);
    std::fflush(stdout);
    ::_exit(3);  // the deleting thread never ends: no destructor may wait for it
  }
  deleter.join();
  std::printf("deleted in %.3f s\n", Seconds(std::chrono::steady_clock::now() - deleting).count());
  return 0;
}
