// rsg_replay: plays the RobotState messages of an MCAP recording back at their original timing,
// as raw frames to a UDP address (what the robot sent: byte for byte the frames the gateway
// received) or as DDS samples.
//
// Exit status: 0 when the file was played (a killed recording's file too: up to its last whole
// chunk, with a warning) or on SIGINT/SIGTERM; 1 when the file cannot be read or is damaged, or
// a send fails; 2 on usage errors.
#include <CLI/CLI.hpp>
#include <array>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <optional>
#include <thread>
#include <unordered_set>

#include "app/dds_options.hpp"
#include "app/discovery_cli.hpp"
#include "app/number_checks.hpp"
#include "app/recording.hpp"
#include "app/stop_on_signal.hpp"
#include "app/tool_main.hpp"
#include "dds/internal/fastdds_compat.hpp"
#include "mcap/mcap_reader.hpp"
#include "rsg/dds/participant.hpp"
#include "rsg/dds/profiles.hpp"
#include "rsg/dds/robot_state.hpp"
#include "rsg/dds/views.hpp"
#include "rsg/error.hpp"
#include "rsg/transport/host_port.hpp"
#include "rsg/transport/udp_socket.hpp"

namespace {

namespace fdds = eprosima::fastdds::dds;
using Clock = std::chrono::steady_clock;
using rsg::app::StopOnSignal;

using namespace rsg::app;  // the main skeleton and the exit statuses

// Sleeps are cut into slices so that a stop request ends a long pause promptly.
constexpr auto kLongestSleep = std::chrono::milliseconds(50);

struct Options {
  std::string file;
  std::string to;
  std::optional<int> domain;
  std::string topic = "robot_state";
  std::vector<std::string> partitions;
  std::string writer_profile = "rsg_state_writer";
  std::vector<std::string> profiles;
  std::string participant_profile = "rsg_participant";
  rsg::dds::DiscoveryOptions discovery;
  int wait_for_readers = 0;
  double speed = 1;
  bool loop = false;
};

/// Where the samples go: raw frames over UDP, or DDS samples.
class Output {
 public:
  virtual ~Output() = default;
  /// False when the sample cannot be sent (the reason is on stderr).
  virtual bool send(const rsg::RobotState& sample) = 0;
  /// After the last send: returns once what was sent has left (or could not).
  virtual void finish() {}
};

class UdpOutput final : public Output {
 public:
  explicit UdpOutput(const rsg::transport::Endpoint& to)
      : to_(to), socket_(rsg::transport::UdpSocket::for_sending_to(to)) {}
  bool send(const rsg::RobotState& sample) override {
    const rsg::wire::EncodeResult frame = codec_.encode(sample, frame_);
    if (!frame) {
      ++unencodable;  // a sample no valid frame could have produced (written by another app)
      return true;
    }
    if (socket_.send_to({frame_.data(), frame.size}, to_)) return true;
    spdlog::error("cannot send to {}: {}", to_.to_string(), std::strerror(errno));
    return false;
  }
  std::uint64_t unencodable = 0;

 private:
  rsg::transport::Endpoint to_;
  rsg::transport::UdpSocket socket_;
  rsg::dds::RobotStateCodec codec_;
  std::array<std::uint8_t, rsg::wire::kMaxFrameBytes> frame_{};
};

class DdsOutput final : public Output {
 public:
  DdsOutput(const Options& options)
      : participant_(*options.domain, options.participant_profile, options.discovery),
        writer_(create_writer(participant_, options)) {
    if (writer_ == nullptr)
      throw rsg::EnvironmentError("cannot create a writer with profile '" + options.writer_profile + "'");
  }
  // Like the gateway's writer, it leaves view filters to the readers (rsg::dds::leave_filtering_to_readers).
  static eprosima::fastdds::dds::DataWriter* create_writer(rsg::dds::Participant& participant,
                                                           const Options& options) {
    eprosima::fastdds::dds::Publisher* publisher = participant.publisher(options.partitions);
    eprosima::fastdds::dds::DataWriterQos qos;
    if (publisher->get_datawriter_qos_from_profile(options.writer_profile, qos) != rsg::dds::kOk)
      return nullptr;
    rsg::dds::leave_filtering_to_readers(qos);
    return publisher->create_datawriter(participant.robot_state_topic(options.topic), qos);
  }

  bool send(const rsg::RobotState& sample) override {
    if (rsg::dds::succeeded(writer_->write(const_cast<rsg::RobotState*>(&sample)))) return true;
    spdlog::error("the DDS writer refused a sample");
    return false;
  }
  fdds::DataWriter& writer() { return *writer_; }
  /// A reliable writer deleted right after its last write takes the unacknowledged samples with
  /// it, and a reader that matched a moment after the writer did never gets them: wait (bounded)
  /// until every matched reader has acknowledged.
  void finish() override {
    if (writer_->wait_for_acknowledgments(rsg::dds::Duration(5, 0)) != rsg::dds::kOk)
      spdlog::warn("not every reader acknowledged the last samples within 5 s");
  }

 private:
  rsg::dds::Participant participant_;
  fdds::DataWriter* writer_;  // owned by participant_
};

/// Sends each RobotState message when it is due: publish times relative to the first message of the
/// pass, divided by the speed, on the steady clock. With --loop each pass starts one mean gap of the
/// pass before it after that pass's last sample (as `rsg_sim --replay --loop` does), so that a looped
/// recording keeps its rate across the wrap.
class Player final : public rsg::mcap::RecordVisitor {
 public:
  Player(Output& output, double speed, const std::atomic<bool>& stop)
      : output_(output), speed_(speed), stop_(stop) {}

  void on_channel(const rsg::mcap::Channel& channel) override {
    if (state_schemas_.contains(channel.schema_id) && channel.message_encoding == "cdr")
      state_channels_.insert(channel.id);
  }
  void on_schema(const rsg::mcap::Schema& schema) override {
    if (rsg::app::is_robot_state_schema(schema.name)) state_schemas_.insert(schema.id);
  }
  bool on_message(const rsg::mcap::Message& message) override {
    if (!state_channels_.contains(message.channel_id)) return !stop_;
    if (!serializer_.deserialize(message.data.bytes, sample_)) {
      ++undecodable;
      return !stop_;
    }
    if (!first_time_) {
      first_time_ = message.publish_time;
      if (!pass_start_) pass_start_ = Clock::now();
    }
    // A publish time going back is sent at once.
    pass_span_ns_ = std::max(
        pass_span_ns_, static_cast<double>(static_cast<std::int64_t>(message.publish_time - *first_time_)));
    wait_until(*pass_start_ + scaled(pass_span_ns_));
    if (stop_) return false;
    if (!output_.send(sample_)) {
      failed = true;
      return false;
    }
    ++sent;
    ++in_pass_;
    return true;
  }

  /// Starts the timeline again (for --loop), one mean gap of the pass just played after its last sample.
  void restart() {
    if (in_pass_ > 0) {
      // One sample has no gap to take the mean of: 1 ms, as rsg_sim --replay takes for one datagram.
      const double gap_ns = in_pass_ > 1 ? pass_span_ns_ / static_cast<double>(in_pass_ - 1) : 1e6;
      *pass_start_ += scaled(pass_span_ns_ + gap_ns);
    }
    first_time_.reset();
    pass_span_ns_ = 0;
    in_pass_ = 0;
  }

  std::uint64_t sent = 0, undecodable = 0;
  bool failed = false;

 private:
  Clock::duration scaled(double recorded_ns) const {
    return std::chrono::duration_cast<Clock::duration>(
        std::chrono::nanoseconds(std::llround(recorded_ns / speed_)));
  }

  void wait_until(Clock::time_point due) const {
    while (!stop_) {
      const auto left = due - Clock::now();
      if (left <= Clock::duration::zero()) return;
      std::this_thread::sleep_for(std::min<Clock::duration>(left, kLongestSleep));
    }
  }

  Output& output_;
  double speed_;
  const std::atomic<bool>& stop_;
  std::unordered_set<std::uint16_t> state_schemas_, state_channels_;
  rsg::app::CdrSerializer serializer_;
  rsg::RobotState sample_;
  std::optional<std::uint64_t> first_time_;      // publish time of the pass's first sample
  std::optional<Clock::time_point> pass_start_;  // when the pass's first sample is due
  double pass_span_ns_ = 0;                      // latest publish time of the pass so far, from its first
  std::uint64_t in_pass_ = 0;                    // samples sent in this pass
};

void add_options(CLI::App& app, Options& options) {
  app.add_option("file", options.file, "MCAP file written by rsg_record")->required();
  auto* to =
      app.add_option("--to", options.to, "Send raw frames to HOST:PORT (as the robot did)")
          ->check([](const std::string& text) {
            return rsg::transport::parse_host_port(text, rsg::transport::HostPortRule::kPortRequired).error();
          });
  auto* domain = app.add_option("--domain", options.domain, "Publish DDS samples on this domain instead")
                     ->check(CLI::Range(0, 232));
  to->excludes(domain);
  app.add_option("--topic", options.topic, "RobotState topic (with --domain)")
      ->check(rsg::app::dds_name(false))
      ->capture_default_str();
  app.add_option("--partition", options.partitions, "DDS partition (with --domain; repeatable)")
      ->check(rsg::app::dds_name(true));
  app.add_option("--writer-profile", options.writer_profile, "DataWriter profile (with --domain)")
      ->capture_default_str();
  app.add_option("--wait-for-readers", options.wait_for_readers,
                 "With --domain: wait up to 10 s until this many readers have matched before playing")
      ->check(CLI::Range(0, 1000000));
  rsg::app::add_profile_options(app, options.profiles, options.participant_profile);
  rsg::app::add_discovery_options(app, options.discovery);
  app.add_option("--speed", options.speed, "Play this many times faster than recorded")
      ->check(rsg::app::positive_number())
      ->capture_default_str();
  app.add_flag("--loop", options.loop,
               "Play the file again and again until SIGINT/SIGTERM, each pass one mean gap between samples "
               "after the one before");
}

void wait_for_readers(fdds::DataWriter& writer, int readers, const std::atomic<bool>& stop) {
  const auto deadline = Clock::now() + std::chrono::seconds(10);
  fdds::PublicationMatchedStatus matched;
  while (!stop && Clock::now() < deadline &&
         writer.get_publication_matched_status(matched) == rsg::dds::kOk && matched.current_count < readers)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  if (matched.current_count < readers)
    spdlog::warn("only {} of {} readers matched; playing anyway", matched.current_count, readers);
}

int run(const Options& options) {
  std::atomic<bool> stop = false;
  StopOnSignal stop_on_signal([&stop] { stop = true; });
  const rsg::mcap::MappedFile file(options.file);

  std::unique_ptr<Output> output;
  if (options.domain) {
    rsg::app::load_profile_options(options.profiles, options.participant_profile);
    rsg::app::check_profiles(
        {{"--writer-profile", rsg::app::NamedProfile::Kind::kDataWriter, options.writer_profile}});
    auto dds = std::make_unique<DdsOutput>(options);
    wait_for_readers(dds->writer(), options.wait_for_readers, stop);
    output = std::move(dds);
  } else {
    output = std::make_unique<UdpOutput>(rsg::transport::Endpoint::parse(options.to));
  }

  Player player(*output, options.speed, stop);
  rsg::mcap::ScanResult result;
  using Status = rsg::mcap::ScanResult::Status;
  // A killed recording loops too (its readable part); a pass that sent nothing ends the loop.
  std::uint64_t sent_before = 0;
  do {
    sent_before = player.sent;
    player.restart();
    result = rsg::mcap::scan(file.bytes(), player);
  } while (options.loop && !stop && !player.failed &&
           (result.status == Status::complete || result.status == Status::truncated) &&
           player.sent > sent_before);

  output->finish();
  std::string summary = fmt::format("sent {} samples", player.sent);
  if (player.undecodable > 0)
    summary += fmt::format(", skipped {} that do not decode as RobotState", player.undecodable);
  if (auto* udp = dynamic_cast<UdpOutput*>(output.get()); udp && udp->unencodable > 0)
    summary += fmt::format(", skipped {} that no valid frame describes", udp->unencodable);
  spdlog::info("{}", summary);
  if (result.status == Status::truncated)
    spdlog::warn("{} ends early (a recorder that was killed?): {} at byte {}; played everything before it",
                 options.file, result.error, result.offset);
  if (result.status == Status::malformed) {
    spdlog::error("{} is damaged at byte {}: {}", options.file, result.offset, result.error);
    return kExitFailure;
  }
  return player.failed ? kExitFailure : kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  rsg::app::init_logging("rsg_replay");
  StopOnSignal::block_stop_signals();  // before Fast DDS starts threads (stop_on_signal.hpp)
  CLI::App app{"Plays an rsg_record MCAP file back as raw frames (--to) or DDS samples (--domain).",
               "rsg_replay"};
  app.footer(
      "Exit status: 0 when played (a killed recording up to its last whole chunk, with a warning) or on "
      "SIGINT/SIGTERM, 1 when the file is damaged or a send fails, 2 usage error or a file that cannot be "
      "opened.");
  Options options;
  add_options(app, options);
  app.final_callback([&options] {
    if (options.to.empty() && !options.domain) throw CLI::RequiredError("--to or --domain");
  });
  return run_main(app, argc, argv, [&] { return run(options); });
}
