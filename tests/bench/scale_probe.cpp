// rsg_bench_scale_probe: the two ends of the scale suite's latency (tests/bench/scale.py), as
// separate processes that can run in different network namespaces of one host.
//
//   rsg_bench_scale_probe send --to HOST:PORT [--rate 1000] --duration S
//       a robot: the e2e suite's stamped full frames (e2e/stamped_frames.hpp: frame index and
//       CLOCK_MONOTONIC send time in elbow_d), paced on absolute deadlines
//   rsg_bench_scale_probe read --domain D [--partition P] [--discovery-server ...]
//                              [--participant-profile NAME] --out FILE
//       a remote reader with rsg_echo's table-mode QoS (reader_realtime): stamps every sample on
//       arrival and, on SIGTERM, writes "index sent_ns received_ns" per sample to FILE;
//       --participant-profile rsg_participant_multicast makes it a multicast reader
//
// Network namespaces share the host's CLOCK_MONOTONIC, so received_ns - sent_ns is the latency
// from the robot's send to the remote reader's receive across the bed's veth links, as the e2e
// suite measures it on loopback. scale.py summarises the samples sent inside its window.
#include <pthread.h>
#include <sys/prctl.h>
#include <time.h>

#include <CLI/CLI.hpp>
#include <atomic>
#include <cerrno>
#include <cmath>
#include <csignal>
#include <fastdds/dds/core/LoanableSequence.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fstream>
#include <iostream>
#include <vector>

#include "app/discovery_cli.hpp"
#include "rsg/dds/fastdds.hpp"
#include "rsg/dds/participant.hpp"
#include "rsg/dds/profiles.hpp"
#include "rsg/dds/views.hpp"
#include "rsg/transport/udp_socket.hpp"
#include "tests/bench/e2e/stamped_frames.hpp"

namespace {

namespace fdds = eprosima::fastdds::dds;
using rsg::bench::monotonic_ns;

struct Arrival {
  std::int64_t index, sent_ns, received_ns;
};

/// Takes samples with loans in the listener, on the thread that delivered them, reading the clock
/// first; the arrivals are allocated up front, so the listener neither allocates nor locks.
class ArrivalLog : public fdds::DataReaderListener {
 public:
  explicit ArrivalLog(std::size_t capacity) : arrivals_(capacity) {}

  void on_data_available(fdds::DataReader* reader) override {
    const std::int64_t received_ns = monotonic_ns();
    fdds::LoanableSequence<rsg::RobotState> samples;
    fdds::SampleInfoSeq infos;
    while (reader->take(samples, infos) == rsg::dds::kOk) {
      for (fdds::LoanableCollection::size_type i = 0; i < samples.length(); ++i) {
        const std::size_t at = count_.load(std::memory_order_relaxed);
        if (!infos[i].valid_data || at == arrivals_.size()) continue;
        const rsg::bench::Stamp stamp = rsg::bench::read_stamp(samples[i]);
        arrivals_[at] = {static_cast<std::int64_t>(stamp.index), stamp.sent_ns, received_ns};
        count_.store(at + 1, std::memory_order_release);
      }
      reader->return_loan(samples, infos);
    }
  }

  void write(const std::string& path) const {
    std::ofstream out(path);
    const std::size_t count = count_.load(std::memory_order_acquire);
    for (std::size_t i = 0; i < count; ++i)
      out << arrivals_[i].index << ' ' << arrivals_[i].sent_ns << ' ' << arrivals_[i].received_ns << '\n';
    if (!out.flush()) throw std::runtime_error("cannot write '" + path + "'");
  }

 private:
  std::vector<Arrival> arrivals_;
  std::atomic<std::size_t> count_{0};
};

sigset_t stop_signals() {
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  return signals;
}

struct ReadOptions {
  int domain = 0;
  std::string topic = "robot_state";
  std::vector<std::string> partitions;
  std::string out;
  std::size_t capacity = 120'000;  // 2 minutes at 1 kHz
  std::string participant_profile = "rsg_participant";
  rsg::dds::DiscoveryOptions discovery;
};

int read(const ReadOptions& options) {
  // Blocked before DDS starts its threads, so that only sigwait below ever takes them.
  const sigset_t signals = stop_signals();
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  rsg::dds::load_profiles({}, options.participant_profile);
  ArrivalLog log(options.capacity);
  {
    rsg::dds::Participant participant(options.domain, options.participant_profile, options.discovery);
    fdds::Topic& topic = *participant.robot_state_topic(options.topic);
    fdds::Subscriber& subscriber = *participant.subscriber(options.partitions);
    fdds::DataReader* reader = subscriber.create_datareader(
        &topic, rsg::dds::load_reader_qos(subscriber, rsg::dds::kRealtimeReaderProfile), &log,
        fdds::StatusMask::data_available());
    if (reader == nullptr) throw std::runtime_error("cannot create a reader on '" + options.topic + "'");
    int signal = 0;
    sigwait(&signals, &signal);
    // Deleting the reader first guarantees no callback runs once the log is read.
    subscriber.delete_datareader(reader);
  }
  log.write(options.out);
  return 0;
}

struct SendOptions {
  std::string to;
  double rate_hz = 1000;
  double duration_s = 10;
};

/// Frame k is due at start + k / rate; a late frame leaves at once (its latency starts at its own
/// stamp), so the average rate holds when the sender is descheduled.
int send(const SendOptions& options) {
  ::prctl(PR_SET_TIMERSLACK, 1UL);  // the default 50 us slack would bunch frames
  const rsg::transport::Endpoint to = rsg::transport::Endpoint::parse(options.to);
  rsg::transport::UdpSocket socket = rsg::transport::UdpSocket::for_sending_to(to);
  rsg::bench::StampedFrames frames;
  const double period_ns = 1e9 / options.rate_hz;
  const auto count = static_cast<std::uint64_t>(options.duration_s * options.rate_hz);
  const std::int64_t start_ns = monotonic_ns();
  std::uint64_t failed = 0;
  for (std::uint64_t k = 0; k < count; ++k) {
    const std::int64_t due = start_ns + std::llround(static_cast<double>(k) * period_ns);
    const timespec deadline{static_cast<time_t>(due / 1'000'000'000), static_cast<long>(due % 1'000'000'000)};
    while (::clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &deadline, nullptr) == EINTR) {
    }
    frames.stamp_now(k);
    if (!socket.send_to(frames.encode(), to)) ++failed;
  }
  if (failed != 0) std::cerr << "rsg_bench_scale_probe: " << failed << " of " << count << " sends failed\n";
  return failed == 0 ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"The scale suite's stamped robot and latency-measuring remote reader",
               "rsg_bench_scale_probe"};
  app.require_subcommand(1);
  SendOptions send_options;
  CLI::App* sender = app.add_subcommand("send", "Send stamped full frames at a rate");
  sender->add_option("--to", send_options.to, "HOST:PORT")->required();
  sender->add_option("--rate", send_options.rate_hz, "Frames per second")->capture_default_str();
  sender->add_option("--duration", send_options.duration_s, "Seconds")->capture_default_str();
  ReadOptions read_options;
  CLI::App* reader = app.add_subcommand("read", "Read RobotState samples until SIGTERM, then write arrivals");
  reader->add_option("--domain", read_options.domain, "DDS domain id")->capture_default_str();
  reader->add_option("--topic", read_options.topic, "RobotState topic")->capture_default_str();
  reader->add_option("--partition", read_options.partitions, "DDS partition (repeatable)");
  reader->add_option("--out", read_options.out, "Where to write 'index sent_ns received_ns' lines")
      ->required();
  reader->add_option("--capacity", read_options.capacity, "Samples kept at most")->capture_default_str();
  reader
      ->add_option("--participant-profile", read_options.participant_profile,
                   "XML participant profile, e.g. rsg_participant_multicast")
      ->capture_default_str();
  rsg::app::add_discovery_options(*reader, read_options.discovery);
  CLI11_PARSE(app, argc, argv);
  try {
    return sender->parsed() ? send(send_options) : read(read_options);
  } catch (const std::exception& error) {
    std::cerr << "rsg_bench_scale_probe: " << error.what() << '\n';
    return 1;
  }
}
