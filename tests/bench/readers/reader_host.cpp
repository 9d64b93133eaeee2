// One process holding N RobotState readers of one kind, for the reader-kind benchmark
// (readers.py): plain readers, readers on a view profile (view_joints), or on an ad-hoc group view
// (groups 2). Every reader takes every sample it gets (a listener, on Fast DDS's receive thread).
//
// With --send-to it is also the robot: once every reader has matched it sends full stamped frames
// (tests/bench/e2e/stamped_frames.hpp) at --rate to the gateway, so that each reader measures the
// one-way latency robot -> gateway -> reader on one clock. It prints "window start" on stderr when
// the measured window begins (after --settle), and after --seconds one JSON line on stdout: kind,
// readers, samples taken, samples without the view's groups, latency p50/p99 (µs), the sender's
// longest gap between two frames (µs) and this process's CPU seconds over the window.
#include <RobotState.h>
#include <pthread.h>
#include <sched.h>
#include <sys/resource.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "rsg/dds/fastdds.hpp"
#include "rsg/dds/owned.hpp"
#include "rsg/dds/participant.hpp"
#include "rsg/dds/profiles.hpp"
#include "rsg/dds/ros2.hpp"
#include "rsg/dds/views.hpp"
#include "rsg/transport/udp_socket.hpp"
#include "tests/bench/e2e/stamped_frames.hpp"

namespace {

namespace fdds = eprosima::fastdds::dds;
using rsg::bench::monotonic_ns;

constexpr std::size_t kMaxLatencies = 200'000;  // per reader: 200 s at 1 kHz

class Taker final : public fdds::DataReaderListener {
 public:
  explicit Taker(std::uint8_t groups) : groups_(groups) { latencies_ns_.resize(kMaxLatencies); }
  void on_data_available(fdds::DataReader* reader) override {
    fdds::SampleInfo info;
    while (reader->take_next_sample(&sample_, &info) == rsg::dds::kOk) {
      if (!info.valid_data) continue;
      const std::int64_t now = monotonic_ns();
      samples.fetch_add(1, std::memory_order_relaxed);
      if ((sample_.group_select() & groups_) != groups_) wrong.fetch_add(1, std::memory_order_relaxed);
      if (measuring.load(std::memory_order_relaxed) && recorded_ < latencies_ns_.size())
        latencies_ns_[recorded_++] = now - rsg::bench::read_stamp(sample_).sent_ns;
    }
  }
  std::atomic<std::uint64_t> samples{0};
  std::atomic<std::uint64_t> wrong{0};
  std::atomic<bool> measuring{false};
  // Read once the readers are gone.
  std::vector<std::int64_t> latencies() const {
    return {latencies_ns_.begin(), latencies_ns_.begin() + recorded_};
  }

 private:
  std::uint8_t groups_;
  rsg::RobotState sample_;
  std::vector<std::int64_t> latencies_ns_;
  std::size_t recorded_ = 0;  // only the listener thread writes it
};

double cpu_seconds() {
  rusage usage{};
  ::getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_utime.tv_sec + usage.ru_stime.tv_sec) +
         static_cast<double>(usage.ru_utime.tv_usec + usage.ru_stime.tv_usec) / 1e6;
}

// Sends stamped frames at `rate_hz` until `stop`; keeps its longest gap between two sends.
void send_frames(const rsg::transport::Endpoint& to, double rate_hz, const std::atomic<bool>& stop,
                 std::int64_t& longest_gap_ns) {
  // On time like a robot: SCHED_FIFO for this thread where the process may (root); the readers
  // keep the default policy. longest_gap_ns says how well that went.
  const sched_param realtime{.sched_priority = 20};
  ::pthread_setschedparam(::pthread_self(), SCHED_FIFO, &realtime);
  rsg::transport::UdpSocket socket = rsg::transport::UdpSocket::for_sending_to(to);
  rsg::bench::StampedFrames frames;
  const auto period = std::chrono::nanoseconds(static_cast<std::int64_t>(1e9 / rate_hz));
  auto next = std::chrono::steady_clock::now();
  std::int64_t last = 0;
  for (std::uint64_t index = 0; !stop.load(std::memory_order_relaxed); ++index) {
    std::this_thread::sleep_until(next);
    next += period;
    frames.stamp_now(index);
    socket.send_to(frames.encode(), to);
    const std::int64_t now = monotonic_ns();
    if (last != 0) longest_gap_ns = std::max(longest_gap_ns, now - last);
    last = now;
  }
}

bool all_matched(const std::vector<fdds::DataReader*>& readers) {
  for (fdds::DataReader* reader : readers) {
    fdds::SubscriptionMatchedStatus status;
    reader->get_subscription_matched_status(status);
    if (status.current_count < 1) return false;
  }
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  int domain = 0;
  std::string kind = "plain";
  int count = 1;
  double seconds = 8;
  double settle = 3;
  double rate_hz = 1000;
  std::string send_to;
  bool ros2 = false;
  std::string qos_profile = rsg::dds::kRealtimeReaderProfile;
  CLI::App app{"Holds N readers of one kind and counts what they take.", "rsg_bench_reader_host"};
  app.add_option("--domain", domain);
  app.add_option("--kind", kind)->check(CLI::IsMember({"plain", "view", "groups"}));
  app.add_option("--count", count)->check(CLI::PositiveNumber);
  app.add_option("--seconds", seconds, "measuring window, after --settle");
  app.add_option("--settle", settle, "seconds of streaming before the window");
  app.add_option("--send-to", send_to, "the gateway's HOST:PORT: be the robot, with stamped frames");
  app.add_option("--rate", rate_hz, "frames per second with --send-to");
  app.add_flag("--ros2", ros2);
  app.add_option("--qos", qos_profile, "reader QoS profile (reader_realtime: data-sharing on this host)");
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
  std::vector<fdds::DataReader*> readers;
  const fdds::DataReaderQos qos = rsg::dds::load_reader_qos(subscriber, qos_profile);
  for (int i = 0; i < count; ++i) {
    takers.push_back(std::make_unique<Taker>(groups));
    if (kind == "plain") {
      plain.push_back(rsg::dds::own(
          subscriber, subscriber.create_datareader(&topic, qos, takers.back().get()), "a reader"));
      readers.push_back(plain.back().get());
    } else {
      const rsg::dds::View view =
          kind == "view" ? rsg::dds::load_view(subscriber, "view_joints") : rsg::dds::group_view(groups);
      views.push_back(
          std::make_unique<rsg::dds::ViewReader>(subscriber, topic, view, qos, takers.back().get()));
      readers.push_back(views.back()->get());
    }
  }

  std::atomic<bool> stop_sending{false};
  std::int64_t longest_gap_ns = 0;
  std::optional<std::thread> sender;
  if (!send_to.empty()) {
    while (!all_matched(readers)) std::this_thread::sleep_for(std::chrono::milliseconds(50));
    sender.emplace(send_frames, rsg::transport::Endpoint::parse(send_to), rate_hz, std::cref(stop_sending),
                   std::ref(longest_gap_ns));
  }
  std::this_thread::sleep_for(std::chrono::duration<double>(settle));
  const auto total = [&] {
    std::uint64_t n = 0;
    for (const auto& taker : takers) n += taker->samples.load();
    return n;
  };
  for (const auto& taker : takers) taker->measuring = true;
  std::fprintf(stderr, "window start\n");
  std::fflush(stderr);
  const std::uint64_t samples_before = total();
  const double cpu_before = cpu_seconds();
  std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
  const double cpu = cpu_seconds() - cpu_before;
  const std::uint64_t samples = total() - samples_before;
  for (const auto& taker : takers) taker->measuring = false;
  // The robot streams on a little, so that whoever measures the gateway over about the same window
  // does not see this end of the stream as a link going down.
  if (sender) std::this_thread::sleep_for(std::chrono::seconds(2));
  stop_sending = true;
  if (sender) sender->join();
  // Readers go before their listeners.
  views.clear();
  plain.clear();

  std::uint64_t wrong = 0;
  std::vector<std::int64_t> latencies;
  for (const auto& taker : takers) {
    wrong += taker->wrong.load();
    const std::vector<std::int64_t> own = taker->latencies();
    latencies.insert(latencies.end(), own.begin(), own.end());
  }
  std::sort(latencies.begin(), latencies.end());
  const auto percentile_us = [&](double p) {
    if (latencies.empty()) return -1.0;
    const auto index =
        std::min(latencies.size() - 1, static_cast<std::size_t>(p * static_cast<double>(latencies.size())));
    return static_cast<double>(latencies[index]) / 1e3;
  };
  std::printf(
      "{\"kind\":\"%s\",\"readers\":%d,\"samples\":%llu,\"wrong\":%llu,\"latency_p50_us\":%.1f,"
      "\"latency_p99_us\":%.1f,\"sender_longest_gap_us\":%lld,\"cpu_s\":%.3f,\"seconds\":%.3f}\n",
      kind.c_str(), count, static_cast<unsigned long long>(samples), static_cast<unsigned long long>(wrong),
      percentile_us(0.50), percentile_us(0.99), static_cast<long long>(longest_gap_ns / 1000), cpu, seconds);
  std::fflush(stdout);
  return wrong == 0 ? 0 : 1;
}
