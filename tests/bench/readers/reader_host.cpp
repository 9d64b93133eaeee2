// One process holding N RobotState readers of one kind, for the reader-kind benchmark
// (readers.py): plain readers, readers on a view profile (view_joints), or on an ad-hoc group view
// (groups 2). Every reader takes every sample it gets (a listener, on Fast DDS's receive thread).
// After --seconds it prints one JSON line: kind, readers, samples taken, samples whose groups the
// view did not ask for, and the process's CPU seconds (getrusage).
#include <RobotState.h>
#include <sys/resource.h>

#include <CLI/CLI.hpp>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "rsg/dds/detail/fastdds_compat.hpp"
#include "rsg/dds/owned.hpp"
#include "rsg/dds/participant.hpp"
#include "rsg/dds/profiles.hpp"
#include "rsg/dds/ros2.hpp"
#include "rsg/dds/views.hpp"

namespace {

namespace fdds = eprosima::fastdds::dds;

class Taker final : public fdds::DataReaderListener {
 public:
  explicit Taker(std::uint8_t groups) : groups_(groups) {}
  void on_data_available(fdds::DataReader* reader) override {
    fdds::SampleInfo info;
    while (reader->take_next_sample(&sample_, &info) == rsg::dds::kOk) {
      if (!info.valid_data) continue;
      samples.fetch_add(1, std::memory_order_relaxed);
      if ((sample_.group_select() & groups_) != groups_) wrong.fetch_add(1, std::memory_order_relaxed);
    }
  }
  std::atomic<std::uint64_t> samples{0};
  std::atomic<std::uint64_t> wrong{0};

 private:
  std::uint8_t groups_;
  rsg::RobotState sample_;
};

double cpu_seconds() {
  rusage usage{};
  ::getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_utime.tv_sec + usage.ru_stime.tv_sec) +
         static_cast<double>(usage.ru_utime.tv_usec + usage.ru_stime.tv_usec) / 1e6;
}

}  // namespace

int main(int argc, char** argv) {
  int domain = 0;
  std::string kind = "plain";
  int count = 1;
  double seconds = 8;
  double settle = 2;
  bool ros2 = false;
  CLI::App app{"Holds N readers of one kind and counts what they take.", "rsg_bench_reader_host"};
  app.add_option("--domain", domain);
  app.add_option("--kind", kind)->check(CLI::IsMember({"plain", "view", "groups"}));
  app.add_option("--count", count)->check(CLI::PositiveNumber);
  app.add_option("--seconds", seconds, "measuring window, after --settle");
  app.add_option("--settle", settle, "seconds before the window: discovery, first samples");
  app.add_flag("--ros2", ros2);
  CLI11_PARSE(app, argc, argv);

  rsg::dds::load_profiles(rsg::dds::default_profiles_dir());
  rsg::dds::Participant participant(domain, "");
  fdds::Subscriber& subscriber = *participant.subscriber();
  fdds::Topic& topic =
      *participant.robot_state_topic(ros2 ? rsg::dds::ros2_topic_name("", "robot_state") : "robot_state",
                                     ros2 ? std::string(rsg::dds::kRos2RobotStateType) : "");
  const std::uint8_t groups = kind == "plain" ? 0 : 0b000100;
  std::vector<std::unique_ptr<Taker>> takers;
  std::vector<rsg::dds::OwnedReader> plain;
  std::vector<std::unique_ptr<rsg::dds::ViewReader>> views;
  const fdds::DataReaderQos qos = rsg::dds::load_reader_qos(subscriber, rsg::dds::kRealtimeReaderProfile);
  for (int i = 0; i < count; ++i) {
    takers.push_back(std::make_unique<Taker>(groups));
    if (kind == "plain")
      plain.push_back(rsg::dds::own(
          subscriber, subscriber.create_datareader(&topic, qos, takers.back().get()), "a reader"));
    else if (kind == "view")
      views.push_back(std::make_unique<rsg::dds::ViewReader>(
          subscriber, topic, rsg::dds::load_view(subscriber, "view_joints"), qos, takers.back().get()));
    else
      views.push_back(std::make_unique<rsg::dds::ViewReader>(subscriber, topic, rsg::dds::group_view(groups),
                                                             qos, takers.back().get()));
  }
  std::this_thread::sleep_for(std::chrono::duration<double>(settle));
  const auto total = [&] {
    std::uint64_t n = 0;
    for (const auto& taker : takers) n += taker->samples.load();
    return n;
  };
  const std::uint64_t samples_before = total();
  const double cpu_before = cpu_seconds();
  std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
  const double cpu = cpu_seconds() - cpu_before;
  const std::uint64_t samples = total() - samples_before;
  std::uint64_t wrong = 0;
  for (const auto& taker : takers) wrong += taker->wrong.load();
  std::printf(
      "{\"kind\":\"%s\",\"readers\":%d,\"samples\":%llu,\"wrong\":%llu,\"cpu_s\":%.3f,\"seconds\":%.3f}\n",
      kind.c_str(), count, static_cast<unsigned long long>(samples), static_cast<unsigned long long>(wrong),
      cpu, seconds);
  std::fflush(stdout);
  // Readers go before their listeners.
  views.clear();
  plain.clear();
  return wrong == 0 ? 0 : 1;
}
