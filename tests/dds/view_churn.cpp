// A client-library reader that comes and goes: for --seconds, ViewReaders on rotating views are
// created, read until they got a sample carrying their groups (or --hold passes), and deleted once
// matched; every --participant-every cycles the participant goes too. Each sample a view reader
// takes must carry the view's groups. Prints "cycles N samples M wrong W unmatched U" (U: readers
// that had not matched the writer 10 s after --hold) and exits 1 when a view received a sample
// without its groups, or 2 for usage errors.
#include <RobotState.h>
#include <execinfo.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "rsg/dds/fastdds.hpp"
#include "rsg/dds/owned.hpp"
#include "rsg/dds/participant.hpp"
#include "rsg/dds/profiles.hpp"
#include "rsg/dds/ros2.hpp"
#include "rsg/dds/views.hpp"

namespace {

// A crash of this process is a finding (issue 29: readers that come and go must not crash anyone),
// and the test's log is all CI keeps: the stack goes to stderr before the default action dumps core.
void print_stack_and_die(int signal) {
  void* frames[64];
  const int count = ::backtrace(frames, 64);
  static constexpr char kHeader[] = "rsg_views_churn: fatal signal, stack:\n";
  [[maybe_unused]] const auto written = ::write(STDERR_FILENO, kHeader, sizeof kHeader - 1);
  ::backtrace_symbols_fd(frames, count, STDERR_FILENO);
  std::signal(signal, SIG_DFL);
  std::raise(signal);
}

}  // namespace

int main(int argc, char** argv) {
  {
    void* warm[1];
    ::backtrace(warm, 1);  // loads libgcc's unwinder now, not inside the signal handler
  }
  for (const int signal : {SIGSEGV, SIGBUS, SIGABRT, SIGFPE}) std::signal(signal, print_stack_and_die);
  int domain = 0;
  std::string topic_name = "robot_state";
  std::vector<std::string> partitions;
  bool ros2 = false;
  double seconds = 10;
  double hold = 1.0;
  int participant_every = 10;
  std::string qos_profile = rsg::dds::kRealtimeReaderProfile;
  bool plain = false;
  CLI::App app{"Creates and deletes view readers in a loop.", "rsg_views_churn"};
  app.add_option("--domain", domain);
  app.add_option("--topic", topic_name);
  app.add_option("--partition", partitions);
  app.add_flag("--ros2", ros2, "the ROS 2 names rsg_gateway --ros2 writes");
  app.add_option("--seconds", seconds);
  app.add_option("--hold", hold, "longest life of one reader, s");
  app.add_option("--participant-every", participant_every)->check(CLI::PositiveNumber);
  app.add_option("--qos", qos_profile, "reader QoS profile");
  app.add_flag("--plain", plain, "plain readers instead of views (the control)");
  CLI11_PARSE(app, argc, argv);

  namespace fdds = eprosima::fastdds::dds;
  using Clock = std::chrono::steady_clock;
  rsg::dds::load_profiles(rsg::dds::default_profiles_dir());
  const std::string topic = ros2 ? rsg::dds::ros2_topic_name("", topic_name) : topic_name;
  const std::string type = ros2 ? std::string(rsg::dds::kRos2RobotStateType) : "";
  // Profiles and ad-hoc group views, each its own filtered topic.
  const std::vector<std::string> profiles = {"view_joints", "view_kinematics", "view_forces", "view_full"};
  const std::vector<std::uint8_t> ad_hoc = {0b000100, 0b101000, 0b000001};

  const auto end =
      Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
  std::unique_ptr<rsg::dds::Participant> participant;
  fdds::Subscriber* subscriber = nullptr;
  std::size_t cycles = 0, samples = 0, wrong = 0, unmatched = 0;
  rsg::RobotState sample;
  fdds::SampleInfo info;
  while (Clock::now() < end) {
    if (cycles % static_cast<std::size_t>(participant_every) == 0) {
      participant.reset();
      participant = std::make_unique<rsg::dds::Participant>(domain, "");
      subscriber = participant->subscriber(partitions);
    }
    fdds::Topic& robot_state = *participant->robot_state_topic(topic, type);
    const std::size_t kinds = profiles.size() + ad_hoc.size();
    const std::size_t pick = cycles % kinds;
    std::unique_ptr<rsg::dds::ViewReader> view;
    rsg::dds::OwnedReader plain_reader;
    if (plain) {
      plain_reader = rsg::dds::own(
          *subscriber,
          subscriber->create_datareader(&robot_state, rsg::dds::load_reader_qos(*subscriber, qos_profile)),
          "a plain reader");
    } else {
      view =
          pick < profiles.size()
              ? std::make_unique<rsg::dds::ViewReader>(*subscriber, robot_state, profiles[pick], qos_profile)
              : std::make_unique<rsg::dds::ViewReader>(*subscriber, robot_state,
                                                       rsg::dds::group_view(ad_hoc[pick - profiles.size()]),
                                                       rsg::dds::load_reader_qos(*subscriber, qos_profile));
    }
    fdds::DataReader* reader = plain ? plain_reader.get() : view->get();
    const std::uint8_t groups = plain ? 0 : view->view().groups;
    const auto give_up =
        Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(hold));
    bool got = false;
    while (!got && Clock::now() < give_up) {
      reader->wait_for_unread_message(rsg::dds::Duration(0, 20'000'000));
      while (reader->take_next_sample(&sample, &info) == rsg::dds::kOk) {
        if (!info.valid_data) continue;
        ++samples;
        got = true;
        if ((sample.group_select() & groups) != groups) ++wrong;
      }
    }
    // A reader deleted while discovery is matching it with a newly found writer can crash its own
    // process (Fast DDS 2.9.1 and 3.1.2, Fast-DDS issue 3303: the match reads the reader's listener
    // twice and the deletion clears it in between; docs/operating.md). This program is about the
    // gateway surviving its readers, so a reader that has not matched yet waits for it first.
    if (!got) {
      fdds::SubscriptionMatchedStatus status;
      const auto match_deadline = Clock::now() + std::chrono::seconds(10);
      while (reader->get_subscription_matched_status(status) == rsg::dds::kOk && status.total_count == 0 &&
             Clock::now() < match_deadline)
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
      if (status.total_count == 0) ++unmatched;
    }
    ++cycles;
  }
  std::printf("cycles %zu samples %zu wrong %zu unmatched %zu\n", cycles, samples, wrong, unmatched);
  return wrong == 0 ? 0 : 1;
}
