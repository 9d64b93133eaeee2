// rsg_record: subscribes to RobotState (whole or through a view) and GatewayStatus, and writes
// every sample to an MCAP file as the CDR bytes a DDS writer sends, with the schema to decode them.
//
// Exit status: 0 after --duration or on SIGINT/SIGTERM with the file finished; 1 when the file
// cannot be written (the error names it; what was recorded stays readable) or DDS fails; 2 on
// usage errors (including unknown profiles).
#include <CLI/CLI.hpp>
#include <chrono>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <iostream>
#include <map>
#include <optional>

#include "matched_writers.hpp"
#include "mcap_writer.hpp"
#include "monitor_options.hpp"
#include "monitor_readers.hpp"
#include "recording.hpp"
#include "rsg/dds/discovery_cli.hpp"
#include "rsg/dds/participant.hpp"
#include "rsg/dds/profiles.hpp"
#include "rsg/dds/views.hpp"
#include "stop_on_signal.hpp"
#include "tool_main.hpp"

namespace {

namespace fdds = eprosima::fastdds::dds;
namespace fs = std::filesystem;
using rsg::tools::StopOnSignal;

using namespace rsg::tools;  // exit statuses

// The recorder takes what has arrived every 10 ms instead of waking for each sample: a recording
// needs no low latency, and a thousand thread wake-ups a second were most of its CPU at 1 kHz. The
// reader's history (reader_logger: 5000 samples) holds far more than 10 ms at any rate rsg reaches.
constexpr auto kBatchPeriod = std::chrono::milliseconds(10);

struct Options : rsg::tools::MonitorOptions {
  fs::path out;
  std::string profile;  // MCAP flavour: "" (omgidl) or "ros2"
  double duration_s = 0;
  double split_mb = 0;
  std::size_t chunk_bytes = rsg::mcap::WriterOptions{}.chunk_bytes;
  bool fsync = false;
};

std::uint64_t now_ns() {
  return static_cast<std::uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                        std::chrono::system_clock::now().time_since_epoch())
                                        .count());
}

/// One MCAP file after another (with --split-size), each complete with its own schemas and channels.
class Recording {
 public:
  Recording(const Options& options, rsg::record::Profile profile)
      : options_(options),
        profile_(profile),
        split_bytes_(static_cast<std::uint64_t>(options.split_mb * 1e6)) {
    open();
  }

  void write_state(const rsg::RobotState& sample, const fdds::SampleInfo& info) {
    ++states;
    write(channels_.robot_state, serializer_.serialize(sample), info);
  }
  void write_status(const rsg::GatewayStatus& sample, const fdds::SampleInfo& info) {
    if (channels_.status == 0) return;
    ++statuses;
    write(channels_.status, serializer_.serialize(sample), info);
  }
  void tick() { writer_->finish_chunk_if_older(now_ns()); }

  /// Finishes the current file. Throws mcap::WriteError.
  void close() {
    writer_->close();
    add_totals();
  }

  std::uint64_t states = 0, statuses = 0;                                                    // received
  std::uint64_t messages = 0, chunks = 0, uncompressed = 0, compressed = 0, file_bytes = 0;  // written
  std::uint64_t syncs = 0, sync_ns = 0;                                                      // --fsync
  std::size_t files = 0;

 private:
  fs::path next_path() const {
    if (split_bytes_ == 0) return options_.out;
    fs::path path = options_.out;
    path.replace_filename(options_.out.stem().string() + "_" + std::to_string(files) +
                          options_.out.extension().string());
    return path;
  }

  void open() {
    const fs::path path = next_path();
    writer_.emplace(path,
                    rsg::mcap::WriterOptions{.profile = std::string(rsg::record::header_profile(profile_)),
                                             .library = "rsg_record",
                                             .chunk_bytes = options_.chunk_bytes,
                                             .sync = options_.fsync});
    channels_ = rsg::record::add_channels(*writer_, profile_, options_.topic, options_.status_topic);
    ++files;
    if (split_bytes_ != 0) std::cerr << "rsg_record: writing " << path.string() << "\n";
  }

  void add_totals() {
    const auto& totals = writer_->totals();
    messages += totals.messages;
    chunks += totals.chunks;
    uncompressed += totals.uncompressed_bytes;
    compressed += totals.compressed_bytes;
    file_bytes += totals.file_bytes;
    syncs += totals.syncs;
    sync_ns += totals.sync_ns;
  }

  void write(std::uint16_t channel, std::span<const std::uint8_t> payload, const fdds::SampleInfo& info) {
    // Log time: when DDS received the sample (not when a batch was taken); publish time: when the
    // gateway wrote it, the robot's frame timing that rsg_replay reproduces.
    const std::int64_t reception_time = info.reception_timestamp.to_ns();
    const std::uint64_t log_time = reception_time > 0 ? static_cast<std::uint64_t>(reception_time) : now_ns();
    const std::int64_t source_time = info.source_timestamp.to_ns();
    const std::uint64_t publish_time = source_time > 0 ? static_cast<std::uint64_t>(source_time) : log_time;
    // The DDS sequence number (its low 32 bits) lets a reader of the file see gaps.
    writer_->write(channel, info.sample_identity.sequence_number().low, log_time, publish_time, payload);
    if (split_bytes_ != 0 && writer_->totals().file_bytes >= split_bytes_) {
      close();
      open();
    }
  }

  const Options& options_;
  rsg::record::Profile profile_;
  std::uint64_t split_bytes_;
  std::optional<rsg::mcap::Writer> writer_;
  rsg::record::Channels channels_;
  rsg::record::CdrSerializer serializer_;
};

/// Counts samples the recorder never got: gaps in each writer's sequence numbers (meaningful
/// without a view, whose filter leaves gaps on purpose) and what DDS reports as lost.
class LossCounter {
 public:
  void add(const fdds::SampleInfo& info) {
    const auto& identity = info.sample_identity;
    const std::uint64_t sequence = identity.sequence_number().to64long();
    auto [last, inserted] = last_.try_emplace(identity.writer_guid(), sequence);
    if (!inserted && sequence > last->second + 1) gaps += sequence - last->second - 1;
    last->second = sequence;
  }
  std::uint64_t gaps = 0;

 private:
  std::map<eprosima::fastrtps::rtps::GUID_t, std::uint64_t> last_;
};

void add_options(CLI::App& app, Options& options) {
  app.add_option("--out", options.out, "MCAP file to write")->required();
  rsg::tools::add_monitor_options(app, options, "records none");
  app.add_option("--profile", options.profile,
                 "MCAP flavour: omgidl (default: rsg's IDL, for Foxglove) or ros2 (ros2msg schemas and the "
                 "channel metadata rosbag2 expects)");
  app.add_option("--duration", options.duration_s,
                 "Stop after this many seconds (default: until SIGINT/SIGTERM)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--split-size", options.split_mb,
                 "Start a new file when one reaches this many MB: FILE_0.mcap, FILE_1.mcap, ...")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--chunk-size", options.chunk_bytes,
                 "Finish a chunk when its records reach this many bytes before compression (or span 1 s): "
                 "smaller chunks lose less to a crash and seek finer, compress worse")
      ->check(CLI::Range(std::size_t{1024}, std::size_t{1} << 30))
      ->capture_default_str();
  app.add_flag("--fsync", options.fsync,
               "fdatasync after every finished chunk and at the end, so that a power loss (not only a crash) "
               "keeps every finished chunk; costs one disk flush per chunk, each blocking the recorder for "
               "the disk's flush latency (the summary line reports the total)");
}

int run(const Options& options, rsg::record::Profile profile) {
  StopOnSignal::block_stop_signals();
  Recording recording(options, profile);  // before DDS: an unwritable path fails at once

  rsg::Participant participant(options.domain, options.participant_profile, options.discovery);
  rsg::tools::MonitorReaders readers(participant, options.topics(), rsg::tools::WakeUp::kPeriodically);
  StopOnSignal stop_on_signal([&readers] { readers.request_stop(); });

  const auto start = std::chrono::steady_clock::now();
  const auto duration = std::chrono::duration<double>(options.duration_s);
  LossCounter loss;
  rsg::tools::MatchedWriters matched_writers("rsg_record", options.topic);
  rsg::RobotState state;
  rsg::GatewayStatus status;
  fdds::SampleInfo info;
  int exit_code = kExitOk;
  const auto write_what_was_received = [&] {
    while (readers.state().take_next_sample(&state, &info) == ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data) continue;
      loss.add(info);
      recording.write_state(state, info);
    }
    while (readers.status() != nullptr &&
           readers.status()->take_next_sample(&status, &info) == ReturnCode_t::RETCODE_OK)
      if (info.valid_data) recording.write_status(status, info);
  };
  try {
    while (!readers.stop_requested() &&
           (options.duration_s == 0 || std::chrono::steady_clock::now() - start < duration)) {
      readers.wait(kBatchPeriod);
      matched_writers.update(readers.state());
      write_what_was_received();
      recording.tick();
    }
    // A slow disk (--fsync, a busy host) can leave the recorder seconds behind DDS: what the reader
    // history already holds at SIGTERM was received and belongs in the file.
    write_what_was_received();
    recording.close();
  } catch (const rsg::mcap::WriteError& error) {
    std::cerr << "rsg_record: " << error.what() << "\n";
    exit_code = kExitFailure;
  }

  fdds::SampleLostStatus lost;
  readers.state().get_sample_lost_status(lost);
  const double ratio = recording.compressed == 0 ? 0
                                                 : static_cast<double>(recording.uncompressed) /
                                                       static_cast<double>(recording.compressed);
  std::cerr << "rsg_record: " << recording.messages << " messages in " << recording.chunks << " chunks, "
            << recording.files << (recording.files == 1 ? " file, " : " files, ") << recording.file_bytes
            << " bytes; compression ratio " << ratio << "; received " << recording.states << " states, "
            << recording.statuses << " statuses"
            << "; dropped " << (options.view_profile.empty() ? loss.gaps : 0) << " (sequence gaps), "
            << lost.total_count << " (lost in DDS)";
  if (options.fsync)
    std::cerr << "; " << recording.syncs << " fsyncs in " << static_cast<double>(recording.sync_ns) / 1e6
              << " ms";
  std::cerr << "\n";
  return exit_code;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Records RobotState and GatewayStatus samples into an MCAP file.", "rsg_record"};
  app.footer(
      "Exit status: 0 after --duration or on SIGINT/SIGTERM (the file finished), 1 when the file cannot be "
      "written (what was recorded stays readable) or DDS fails, 2 usage error.");
  Options options;
  add_options(app, options);
  if (const auto stop = parse_command_line(app, argc, argv)) return *stop;
  const auto profile = rsg::record::parse_profile(options.profile);
  if (!profile) {
    std::cerr << "rsg_record: --profile must be omgidl or ros2, not '" << options.profile << "'\n";
    return kExitUsage;
  }
  if (*profile == rsg::record::Profile::ros2 && !rsg::record::has_ros2_schemas()) {
    std::cerr << "rsg_record: this build has no ros2/rsg_msgs/msg/RobotState.msg, so no --profile ros2\n";
    return kExitUsage;
  }
  if (*profile == rsg::record::Profile::ros2 && !options.status_topic.empty() &&
      !rsg::record::has_ros2_status_schema())
    std::cerr
        << "rsg_record: warning: this build has no ros2/rsg_msgs/msg/GatewayStatus.msg, so a --profile ros2 "
           "recording leaves '"
        << options.status_topic << "' out\n";
  if (const auto stop = load_profiles("rsg_record", options.profiles, options.participant_profile))
    return *stop;
  return run_reporting_errors("rsg_record", [&] { return run(options, *profile); });
}
