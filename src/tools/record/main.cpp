// rsg_record: subscribes to RobotState (whole or through a view) and GatewayStatus, and writes
// every sample to an MCAP file as the CDR bytes a DDS writer sends, with the schema to decode them.
//
// Exit status: 0 after --duration or on SIGINT/SIGTERM with the file finished; 1 when the file
// cannot be written (the error names it; what was recorded stays readable) or DDS fails; 2 on
// usage errors (including unknown profiles). With --recover FILE: 0 when FILE was read to its end
// or cut off (a killed recorder's file), 1 when it is damaged inside or --out cannot be written.
#include <CLI/CLI.hpp>
#include <chrono>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <map>
#include <optional>

#include "dds/internal/fastdds_compat.hpp"
#include "discovery_cli.hpp"
#include "matched_writers.hpp"
#include "mcap_recover.hpp"
#include "mcap_writer.hpp"
#include "monitor_options.hpp"
#include "monitor_readers.hpp"
#include "recording.hpp"
#include "rsg/dds/participant.hpp"
#include "rsg/dds/profiles.hpp"
#include "rsg/dds/views.hpp"
#include "stop_on_signal.hpp"
#include "tool_main.hpp"

namespace {

namespace fdds = eprosima::fastdds::dds;
namespace fs = std::filesystem;
using rsg::app::StopOnSignal;

using namespace rsg::app;  // the main skeleton and the exit statuses

// The recorder takes what has arrived every 10 ms instead of waking for each sample: a recording
// needs no low latency, and a thousand thread wake-ups a second were most of its CPU at 1 kHz. The
// reader's history (reader_logger: 5000 samples) holds far more than 10 ms at any rate rsg reaches.
constexpr auto kBatchPeriod = std::chrono::milliseconds(10);

struct Options : rsg::app::MonitorOptions {
  fs::path out;
  std::string profile;  // MCAP flavour: "" (omgidl) or "ros2"
  double duration_s = 0;
  double split_mb = 0;
  std::size_t chunk_bytes = rsg::mcap::WriterOptions{}.chunk_bytes;
  bool fsync = false;
  fs::path recover;  // --recover: copy this damaged file to --out instead of recording
};

std::uint64_t now_ns() {
  return static_cast<std::uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                        std::chrono::system_clock::now().time_since_epoch())
                                        .count());
}

/// One MCAP file after another (with --split-size), each complete with its own schemas and channels.
class Recording {
 public:
  Recording(const Options& options, rsg::app::Profile profile)
      : options_(options),
        profile_(profile),
        split_bytes_(static_cast<std::uint64_t>(options.split_mb * 1e6)) {
    open();
  }

  /// Adds a sample to the batch that write_batch() writes.
  void add_state(const rsg::RobotState& sample, const fdds::SampleInfo& info) {
    ++states;
    add(channels_.robot_state, serializer_.serialize(sample), info);
  }
  void add_status(const rsg::GatewayStatus& sample, const fdds::SampleInfo& info) {
    if (channels_.status == 0) return;
    ++statuses;
    add(channels_.status, serializer_.serialize(sample), info);
  }

  /// Writes the batch in log time order. Each reader's samples come in the order DDS delivers them and
  /// the status reader's are taken after the state reader's, so a batch is sorted first; a sample
  /// stamped before one already written (taken a batch late, or a reliable reader's repaired sample,
  /// delivered in sequence order after later ones) is logged at the latest log time written, since
  /// MCAP readers expect log times never to go back (`mcap doctor` warns about every one that does).
  void write_batch() {
    std::stable_sort(batch_.begin(), batch_.end(),
                     [](const Pending& a, const Pending& b) { return a.log_time < b.log_time; });
    for (const Pending& pending : batch_) {
      std::uint64_t log_time = pending.log_time;
      if (log_time < last_log_time_) {
        log_time = last_log_time_;
        ++raised;
      }
      last_log_time_ = log_time;
      write(pending.channel, pending.sequence, log_time, pending.publish_time,
            std::span<const std::uint8_t>(batch_bytes_).subspan(pending.offset, pending.size));
    }
    batch_.clear();
    batch_bytes_.clear();
  }
  void tick() {
    if (writer_) writer_->finish_chunk_if_older(now_ns());
  }

  /// After a WriteError: the writer ended the file as well as it could; count what it holds.
  void count_failed_file() {
    if (!writer_) return;
    add_totals();
    writer_.reset();
  }

  /// Finishes the current file. Throws mcap::WriteError.
  void close() {
    write_batch();
    if (writer_) finish_file();
  }

  std::uint64_t states = 0, statuses = 0;                                                    // received
  std::uint64_t messages = 0, chunks = 0, uncompressed = 0, compressed = 0, file_bytes = 0;  // written
  std::uint64_t syncs = 0, sync_ns = 0;                                                      // --fsync
  std::uint64_t raised = 0;  // log times raised to the latest one written (write_batch)
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
    writer_.emplace(path, rsg::mcap::WriterOptions{.profile = std::string(rsg::app::header_profile(profile_)),
                                                   .library = "rsg_record",
                                                   .chunk_bytes = options_.chunk_bytes,
                                                   .sync = options_.fsync});
    channels_ = rsg::app::add_channels(*writer_, profile_, options_.topic, options_.status_topic);
    ++files;
    if (split_bytes_ != 0) spdlog::info("writing {}", path.string());
  }

  void finish_file() {
    writer_->close();
    add_totals();
    writer_.reset();
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

  struct Pending {
    std::uint16_t channel;
    std::uint32_t sequence;
    std::uint64_t log_time, publish_time;
    std::size_t offset, size;  // in batch_bytes_
  };

  void add(std::uint16_t channel, std::span<const std::uint8_t> payload, const fdds::SampleInfo& info) {
    // Log time: when DDS received the sample (not when a batch was taken); publish time: when the
    // gateway wrote it, the robot's frame timing that rsg_replay reproduces.
    const std::int64_t reception_time = info.reception_timestamp.to_ns();
    const std::uint64_t log_time = reception_time > 0 ? static_cast<std::uint64_t>(reception_time) : now_ns();
    const std::int64_t source_time = info.source_timestamp.to_ns();
    const std::uint64_t publish_time = source_time > 0 ? static_cast<std::uint64_t>(source_time) : log_time;
    // The DDS sequence number (its low 32 bits) lets a reader of the file see gaps.
    batch_.push_back({channel, info.sample_identity.sequence_number().low, log_time, publish_time,
                      batch_bytes_.size(), payload.size()});
    batch_bytes_.insert(batch_bytes_.end(), payload.begin(), payload.end());
  }

  void write(std::uint16_t channel, std::uint32_t sequence, std::uint64_t log_time,
             std::uint64_t publish_time, std::span<const std::uint8_t> payload) {
    // After a split the next file is opened by the next message, so that none is left empty.
    if (!writer_) open();
    writer_->write(channel, sequence, log_time, publish_time, payload);
    if (split_bytes_ != 0 && writer_->totals().file_bytes >= split_bytes_) finish_file();
  }

  const Options& options_;
  rsg::app::Profile profile_;
  std::uint64_t split_bytes_;
  std::optional<rsg::mcap::Writer> writer_;
  rsg::app::Channels channels_;
  rsg::app::CdrSerializer serializer_;
  std::vector<Pending> batch_;
  std::vector<std::uint8_t> batch_bytes_;
  std::uint64_t last_log_time_ = 0;
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
  std::map<rsg::dds::rtps::GUID_t, std::uint64_t> last_;
};

void add_options(CLI::App& app, Options& options) {
  app.add_option("--out", options.out, "MCAP file to write")->required();
  rsg::app::add_monitor_options(app, options, "records none");
  app.add_option("--profile", options.profile,
                 "MCAP flavour: omgidl (default: rsg's IDL, for Foxglove) or ros2 (ros2msg schemas and the "
                 "channel metadata rosbag2 expects)");
  app.add_option("--duration", options.duration_s,
                 "Stop after this many seconds (default: until SIGINT/SIGTERM)")
      ->check(CLI::NonNegativeNumber);
  app.add_option(
         "--recover", options.recover,
         "Do not record: write what FILE (a recording whose recorder was killed) holds up to its last "
         "whole chunk to --out as a finished, indexed file, and exit")
      ->check(CLI::ExistingFile);
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

/// --recover: the damaged file's readable part, finished, in --out. Exit 0 when the file was
/// truncated or whole, 1 when it is damaged inside (what came before the damage is still written).
int recover(const Options& options) {
  const rsg::mcap::MappedFile damaged(options.recover);
  const auto result = rsg::mcap::recover(damaged.bytes(), options.out,
                                         {.chunk_bytes = options.chunk_bytes, .sync = options.fsync});
  using Status = rsg::mcap::ScanResult::Status;
  spdlog::info("recovered {} messages in {} chunks from {} into {}{}", result.written.messages,
               result.written.chunks, options.recover.string(), options.out.string(),
               result.unreadable > 0 ? fmt::format("; left out {} on undescribed channels", result.unreadable)
                                     : std::string());
  if (result.scan.status == Status::truncated)
    spdlog::warn("{} ends early ({} at byte {}): everything before it was recovered",
                 options.recover.string(), result.scan.error, result.scan.offset);
  if (result.scan.status == Status::malformed) {
    spdlog::error("{} is damaged at byte {}: {}; what came before was recovered", options.recover.string(),
                  result.scan.offset, result.scan.error);
    return kExitFailure;
  }
  return kExitOk;
}

int run(const Options& options, rsg::app::Profile profile) {
  Recording recording(options, profile);  // before DDS: an unwritable path fails at once

  rsg::dds::WriterDirectory writers;  // what discovery shows, should no writer match
  rsg::dds::Participant participant(options.domain, options.participant_profile, options.discovery,
                                    writers.listener());
  rsg::app::MonitorReaders readers(participant, options.topics(), rsg::app::WakeUp::kPeriodically);
  StopOnSignal stop_on_signal([&readers] { readers.request_stop(); });

  const auto start = std::chrono::steady_clock::now();
  const auto duration = std::chrono::duration<double>(options.duration_s);
  LossCounter loss;
  rsg::app::MatchedWriters matched_writers(options.topic, writers, options.domain);
  rsg::RobotState state;
  rsg::GatewayStatus status;
  fdds::SampleInfo info;
  int exit_code = kExitOk;
  const auto write_what_was_received = [&] {
    while (readers.state().take_next_sample(&state, &info) == rsg::dds::kOk) {
      if (!info.valid_data) continue;
      matched_writers.on_sample();
      loss.add(info);
      recording.add_state(state, info);
    }
    while (readers.status() != nullptr && readers.status()->take_next_sample(&status, &info) == rsg::dds::kOk)
      if (info.valid_data) recording.add_status(status, info);
    recording.write_batch();
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
    spdlog::error("{}", error.what());
    recording.count_failed_file();
    exit_code = kExitFailure;
  }

  fdds::SampleLostStatus lost;
  readers.state().get_sample_lost_status(lost);
  const double ratio = recording.compressed == 0 ? 0
                                                 : static_cast<double>(recording.uncompressed) /
                                                       static_cast<double>(recording.compressed);
  std::string summary = fmt::format(
      "{} messages in {} chunks, {} {}, {} bytes; compression ratio {:g}; received {} states, {} statuses; "
      "dropped {} (sequence gaps), {} (lost in DDS)",
      recording.messages, recording.chunks, recording.files, recording.files == 1 ? "file" : "files",
      recording.file_bytes, ratio, recording.states, recording.statuses,
      options.view_profile.empty() ? loss.gaps : 0, lost.total_count);
  if (recording.raised > 0)
    summary += fmt::format("; {} log times raised to keep their order", recording.raised);
  if (options.fsync)
    summary +=
        fmt::format("; {} fsyncs in {:g} ms", recording.syncs, static_cast<double>(recording.sync_ns) / 1e6);
  spdlog::info("{}", summary);
  return exit_code;
}

}  // namespace

int main(int argc, char** argv) {
  rsg::app::init_logging("rsg_record");
  StopOnSignal::block_stop_signals();  // before Fast DDS starts threads (stop_on_signal.hpp)
  CLI::App app{"Records RobotState and GatewayStatus samples into an MCAP file.", "rsg_record"};
  app.footer(
      "Exit status: 0 after --duration or on SIGINT/SIGTERM (the file finished), 1 when the file cannot be "
      "written (what was recorded stays readable) or DDS fails, 2 usage error. --recover: 0 when FILE read "
      "to "
      "its end or was cut off, 1 when it is damaged inside.");
  Options options;
  add_options(app, options);
  return run_main(app, argc, argv, [&] {
    if (!options.recover.empty()) {
      if (fs::exists(options.out) && fs::equivalent(options.out, options.recover))
        throw rsg::InputError("--recover writes a new file: --out must be another path");
      return recover(options);
    }
    const auto profile = rsg::app::parse_profile(options.profile);
    if (!profile) throw rsg::InputError("--profile must be omgidl or ros2, not '" + options.profile + "'");
    if (*profile == rsg::app::Profile::ros2 && !rsg::app::has_ros2_schemas())
      throw rsg::InputError("this build has no ros2/rsg_msgs/msg/RobotState.msg, so no --profile ros2");
    if (*profile == rsg::app::Profile::ros2 && !options.status_topic.empty() &&
        !rsg::app::has_ros2_status_schema())
      spdlog::warn(
          "this build has no ros2/rsg_msgs/msg/GatewayStatus.msg, so a --profile ros2 recording leaves "
          "'{}' out",
          options.status_topic);
    rsg::dds::load_profiles(options.profiles, options.participant_profile);
    return run(options, *profile);
  });
}
