// rsg_deadline_probe: what a real-time consumer of the gateway sees, as timestamped JSON lines.
// Test helper, not a product.
//
// Reads the RobotState topic with the `reader_realtime` profile (best effort, 100 ms requested
// deadline; --qos another) and the gateway's status topic, and prints one line per event:
//   {"t":12.345678,"event":"sample","packet_number":3,"time":1042}
//   {"t":12.445901,"event":"deadline_missed","total_count":1}
//   {"t":12.446020,"event":"status","link_up":false,"lost":0,...}   (the --stats-file form)
// `t` is CLOCK_MONOTONIC in seconds (std::chrono::steady_clock), the clock of Python's
// time.monotonic(), so tests compare it with their own timestamps. Events are timestamped in the
// listener callback, on the DDS thread that delivers them; printing happens on the main thread.
#include <GatewayStatusPubSubTypes.h>
#include <RobotState.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <condition_variable>
#include <csignal>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <iostream>
#include <mutex>
#include <string>
#include <vector>

#include "rsg/dds/fastdds.hpp"
#include "rsg/dds/participant.hpp"
#include "rsg/dds/profiles.hpp"
#include "rsg/dds/views.hpp"
#include "status/status_sample.hpp"

namespace {

namespace fdds = eprosima::fastdds::dds;

double monotonic_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

std::string timestamped(const char* event, const std::string& rest) {
  char head[64];
  std::snprintf(head, sizeof head, "{\"t\":%.6f,\"event\":\"%s\"", monotonic_seconds(), event);
  return std::string(head) + rest + "}\n";
}

/// Lines produced on DDS threads, printed by the main thread.
class EventLog {
 public:
  void add(std::string line) {
    const std::lock_guard lock(mutex_);
    pending_ += line;
    wake_.notify_one();
  }

  /// Waits up to `timeout` for events, then prints what is pending.
  void flush_within(std::chrono::milliseconds timeout) {
    std::string lines;
    {
      std::unique_lock lock(mutex_);
      wake_.wait_for(lock, timeout, [this] { return !pending_.empty(); });
      lines.swap(pending_);
    }
    std::cout << lines << std::flush;
  }

 private:
  std::mutex mutex_;
  std::condition_variable wake_;
  std::string pending_;
};

class StateListener : public fdds::DataReaderListener {
 public:
  explicit StateListener(EventLog& log) : log_(log) {}

  void on_data_available(fdds::DataReader* reader) override {
    fdds::SampleInfo info;
    while (reader->take_next_sample(&sample_, &info) == rsg::dds::kOk)
      if (info.valid_data)
        log_.add(timestamped("sample", ",\"packet_number\":" + std::to_string(sample_.packet_number()) +
                                           ",\"time\":" + std::to_string(sample_.time())));
  }

  void on_requested_deadline_missed(fdds::DataReader*,
                                    const fdds::RequestedDeadlineMissedStatus& status) override {
    log_.add(timestamped("deadline_missed", ",\"total_count\":" + std::to_string(status.total_count)));
  }

 private:
  EventLog& log_;
  rsg::RobotState sample_;  // taken into in place: no allocation per sample
};

class StatusListener : public fdds::DataReaderListener {
 public:
  explicit StatusListener(EventLog& log) : log_(log) {}

  void on_data_available(fdds::DataReader* reader) override {
    fdds::SampleInfo info;
    while (reader->take_next_sample(&sample_, &info) == rsg::dds::kOk) {
      if (!info.valid_data) continue;
      // The --stats-file object without its braces, appended after "t" and "event".
      const std::string json = rsg::status::to_json(rsg::status::from_status_sample(sample_));
      log_.add(timestamped("status", "," + json.substr(1, json.size() - 2)));
    }
  }

 private:
  EventLog& log_;
  rsg::GatewayStatus sample_;
};

/// Deletes a reader of the participant's subscriber when it goes out of scope, before its listener.
struct ReaderGuard {
  fdds::Subscriber* subscriber;
  fdds::DataReader* reader;
  ~ReaderGuard() {
    if (reader) subscriber->delete_datareader(reader);
  }
};

volatile std::sig_atomic_t g_stop = 0;

}  // namespace

int main(int argc, char** argv) {
  int domain = 0;
  std::string state_topic = "robot_state";
  std::string status_topic = "rsg_gateway_status";
  std::string qos_profile = rsg::dds::kRealtimeReaderProfile;
  double timeout_s = 30;
  CLI::App app("Prints RobotState arrivals, deadline misses and GatewayStatus as timestamped JSON lines",
               "rsg_deadline_probe");
  app.add_option("--domain", domain);
  app.add_option("--topic", state_topic);
  app.add_option("--status-topic", status_topic);
  app.add_option("--qos", qos_profile, "RobotState reader profile")->capture_default_str();
  app.add_option("--timeout", timeout_s, "Seconds to run (SIGTERM ends it earlier)");
  CLI11_PARSE(app, argc, argv);
  std::signal(SIGTERM, [](int) { g_stop = 1; });

  rsg::dds::load_profiles(rsg::dds::default_profiles_dir());
  rsg::dds::Participant participant(domain, "rsg_participant");
  fdds::Subscriber* subscriber = participant.subscriber();
  EventLog log;
  StateListener state_listener(log);
  StatusListener status_listener(log);

  fdds::Topic* states = participant.robot_state_topic(state_topic);
  const ReaderGuard state_reader{
      subscriber, subscriber->create_datareader(states, rsg::dds::load_reader_qos(*subscriber, qos_profile),
                                                &state_listener)};
  fdds::Topic* statuses =
      participant.topic(status_topic, fdds::TypeSupport(new rsg::GatewayStatusPubSubType()));
  const ReaderGuard status_reader{subscriber, subscriber->create_datareader_with_profile(
                                                  statuses, "rsg_status_reader", &status_listener)};
  if (!state_reader.reader || !status_reader.reader) {
    std::cerr << "rsg_deadline_probe: cannot create the readers\n";
    return 2;
  }

  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (!g_stop && std::chrono::steady_clock::now() < deadline)
    log.flush_within(std::chrono::milliseconds(50));
  log.flush_within(std::chrono::milliseconds(0));
  return 0;
}
