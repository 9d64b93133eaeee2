// rsg_record: subscribes to RobotState (whole or through a view) and GatewayStatus, and writes
// every sample to an MCAP file as the CDR bytes a DDS writer sends, with the schema to decode them.
//
// With --trigger it records only around events (SIGUSR1, the gateway's link going down, invalid
// frames): the last --pre seconds of samples wait in memory, bounded by --trigger-buffer, and an
// event writes them and the --post seconds after it to a file of their own.
//
// Exit status: 0 after --duration or on SIGINT/SIGTERM with the file finished; 1 when the file
// cannot be written (the error names it; what was recorded stays readable), DDS fails or no writer
// of the topic ever matched (a wrong domain or partition: the file holds no state); 2 on
// usage errors (including unknown profiles). With --recover FILE: 0 when FILE was read to its end
// or cut off (a killed recorder's file), 1 when it is damaged inside or --out cannot be written.
#include <pthread.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <csignal>
#include <ctime>
#include <deque>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "app/discovery_cli.hpp"
#include "app/file_options.hpp"
#include "app/matched_writers.hpp"
#include "app/monitor_options.hpp"
#include "app/monitor_readers.hpp"
#include "app/number_checks.hpp"
#include "app/recording.hpp"
#include "app/recording_order.hpp"
#include "app/stop_on_signal.hpp"
#include "app/tool_main.hpp"
#include "dds/internal/fastdds_compat.hpp"
#include "mcap/mcap_recover.hpp"
#include "mcap/mcap_writer.hpp"
#include "rsg/dds/participant.hpp"
#include "rsg/dds/profiles.hpp"
#include "rsg/dds/views.hpp"
#include "status/status_sample.hpp"

namespace {

namespace fdds = eprosima::fastdds::dds;
namespace fs = std::filesystem;
using rsg::app::StopOnSignal;

using namespace rsg::app;  // the main skeleton and the exit statuses

// The recorder takes what has arrived every 10 ms instead of waking for each sample: a recording
// needs no low latency, and a thousand thread wake-ups a second were most of its CPU at 1 kHz. The
// reader's history (reader_logger: 5000 samples) holds far more than 10 ms at any rate rsg reaches.
constexpr auto kBatchPeriod = std::chrono::milliseconds(10);
// How long a sample waits for the samples published before it (recording_order.hpp): a reader that
// joins a running gateway gets the writer's history after the live samples, later still on a busy
// host. Longer costs memory (this much of the stream) and what a SIGKILL loses.
constexpr auto kHold = std::chrono::milliseconds(500);

struct Options : rsg::app::MonitorOptions {
  fs::path out;
  std::string profile;  // MCAP flavour: "" (omgidl) or "ros2"
  double duration_s = 0;
  double split_mb = 0;
  // Retention of the split files (0: no limit), oldest removed first.
  std::size_t max_files = 0;
  double max_mb = 0;
  double max_age_s = 0;
  std::size_t chunk_bytes = rsg::mcap::WriterOptions{}.chunk_bytes;
  bool fsync = false;
  fs::path recover;  // --recover: copy this damaged file to --out instead of recording
  // --trigger: files only around events, each with the --pre seconds before it and --post after.
  std::vector<std::string> triggers;
  double pre_s = 10;
  double post_s = 10;
  double trigger_buffer_mb = 64;  // what the --pre window may hold in memory
  // An event's own bounds: an event that triggers keep extending is closed (and kept) at either,
  // and the next trigger starts a new one.
  double event_max_s = 60;
  double event_max_mb = 100;

  bool triggered() const { return !triggers.empty(); }
  bool trigger_on(std::string_view what) const {
    return std::find(triggers.begin(), triggers.end(), what) != triggers.end();
  }
};

/// --trigger signal: SIGUSR1, blocked in every thread (before DDS starts its threads) and taken by
/// the recording loop without waiting, as StopOnSignal takes the stop signals: no handler.
class TriggerSignal {
 public:
  static void block() {
    const sigset_t signals = usr1();
    pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  }
  /// True once per SIGUSR1 that arrived since the last call (signals of one kind merge while pending).
  static bool take() {
    const sigset_t signals = usr1();
    const timespec now{0, 0};
    return sigtimedwait(&signals, nullptr, &now) == SIGUSR1;
  }

 private:
  static sigset_t usr1() {
    sigset_t signals;
    sigemptyset(&signals);
    sigaddset(&signals, SIGUSR1);
    return signals;
  }
};

std::uint64_t now_ns() {
  return static_cast<std::uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                        std::chrono::system_clock::now().time_since_epoch())
                                        .count());
}

/// One MCAP file after another (with --split-size, or one per event with --trigger), each complete
/// with its own schemas and channels. Samples are written in publication order (PublicationOrder:
/// held until `kHold` after their arrival), their log times raised where that order puts a
/// later-received sample first.
class Recording {
 public:
  Recording(const Options& options, rsg::app::Profile profile)
      : options_(options),
        profile_(profile),
        split_bytes_(static_cast<std::uint64_t>(options.split_mb * 1e6)),
        numbered_(split_bytes_ != 0 || options.triggered()),
        pre_ns_(static_cast<std::uint64_t>(options.pre_s * 1e9)),
        post_ns_(static_cast<std::uint64_t>(options.post_s * 1e9)),
        buffer_bytes_(static_cast<std::uint64_t>(options.trigger_buffer_mb * 1e6)),
        event_max_ns_(static_cast<std::uint64_t>(options.event_max_s * 1e9)),
        event_max_bytes_(event_bytes_bound(options)),
        run_stamp_(run_stamp()),
        order_(kHold) {
    if (numbered_) adopt_earlier_files();
    if (!options.triggered()) {
      open();
      return;
    }
    // A triggered recording takes samples before it opens a file: the channel ids every file gets
    // from add_channels (the state's first, then the status's), checked as each file is opened.
    const bool status = !options.status_topic.empty() &&
                        (profile == rsg::app::Profile::omgidl || rsg::app::has_ros2_status_schema());
    channels_ = {.robot_state = 1, .status = static_cast<std::uint16_t>(status ? 2 : 0)};
  }

  /// Adds a sample to those waiting for their place in the file.
  void add_state(const rsg::RobotState& sample, const fdds::SampleInfo& info) {
    ++states;
    // A view's filter leaves holes in the writer's sequence numbers on purpose.
    add(channels_.robot_state, options_.view_profile.empty(), serializer_.serialize(sample), info);
  }
  void add_status(const rsg::GatewayStatus& sample, const fdds::SampleInfo& info) {
    if (channels_.status == 0) return;
    ++statuses;
    add(channels_.status, true, serializer_.serialize(sample), info);
    // --trigger link-down: the link going from up to down (not a gateway that starts without its robot).
    if (options_.trigger_on("link-down")) {
      if (link_up_.value_or(false) && !sample.link_up()) trigger(log_time_of(info), "the link went down");
      link_up_ = sample.link_up();
    }
    // --trigger invalid: the gateway counted invalid frames since its previous status sample (the
    // counters are totals: the first sample only sets the baseline).
    if (options_.trigger_on("invalid")) {
      const std::uint64_t invalid = rsg::status::from_status_sample(sample).ingress.invalid_total();
      if (invalid_ && invalid > *invalid_)
        trigger(log_time_of(info), fmt::format("{} invalid frames", invalid - *invalid_));
      invalid_ = invalid;
    }
  }

  /// --trigger: an event at `at_ns` (log-time clock). Opens the event's file with what the --pre
  /// window holds of the time before, and records until --post after it; an event while one is
  /// being recorded extends it.
  void trigger(std::uint64_t at_ns, std::string_view why) {
    ++triggers;
    if (writer_) {
      // Never past the event's own bound: triggers that keep coming (an attacker's invalid frames)
      // would otherwise keep one file open and growing.
      event_end_ = std::min(std::max(event_end_, at_ns + post_ns_), event_start_ + event_max_ns_);
      spdlog::info("{}: event {} extended to {:g} s after it", why, events - 1, options_.post_s);
      return;
    }
    event_start_ = at_ns;
    event_end_ = std::min(at_ns + post_ns_, at_ns + event_max_ns_);
    ++events;
    spdlog::info("{}: event {}, writing {} (up to {:g} s before, {:g} s after)", why, events - 1,
                 next_path().string(), options_.pre_s, options_.post_s);
    open();
    for (const auto& sample : pre_)
      if (sample.log_time + pre_ns_ >= at_ns) write_to_file(sample, sample.log_time);
  }

  /// Writes what is due at `now` in publication order. A sample placed after one received later is
  /// logged at the latest log time written, since MCAP readers expect log times never to go back
  /// (`mcap doctor` warns about every one that does).
  void write_due(std::uint64_t now) {
    order_.release(now, [this](const rsg::app::PublicationOrder::Sample& sample) { write(sample); });
  }
  void tick() {
    const std::uint64_t now = now_ns();
    if (writer_) writer_->finish_chunk_if_older(now);
    // An event's last samples are out of PublicationOrder `kHold` after they arrived.
    if (options_.triggered() && writer_ &&
        now >= event_end_ + static_cast<std::uint64_t>(std::chrono::nanoseconds(kHold).count()))
      finish_event(end_bound());
    if (options_.max_age_s > 0) apply_retention();
  }

  /// After a WriteError: the writer ended the file as well as it could; count what it holds.
  void count_failed_file() {
    if (!writer_) return;
    add_totals();
    writer_.reset();
  }

  /// Writes every sample still held and finishes the current file (--trigger: the event being
  /// recorded, if any; the --pre window is left out). Throws mcap::WriteError.
  void close() {
    order_.release_all([this](const rsg::app::PublicationOrder::Sample& sample) { write(sample); });
    if (writer_) finish_file(true);
  }

  rsg::app::PublicationOrder::Counts state_counts() const { return order_.counts(channels_.robot_state); }

  /// What this run wrote, for a message saying it holds no state: the file, or that none was written
  /// (--trigger without an event), or how many (--split-size).
  std::string written() const {
    if (files == 0) return "no file was written";
    if (files == 1) return next_path_of(0).string() + " holds no state";
    return fmt::format("its {} files ({}, ...) hold no state", files, next_path_of(0).string());
  }

  std::uint64_t states = 0, statuses = 0;  // received
  std::uint64_t states_written = 0;
  std::uint64_t messages = 0, chunks = 0, uncompressed = 0, compressed = 0, file_bytes = 0;  // written
  std::uint64_t syncs = 0, sync_ns = 0;                                                      // --fsync
  std::uint64_t raised = 0;  // log times raised to the latest one written
  std::size_t files = 0;
  std::size_t removed = 0;                 // by retention
  std::uint64_t triggers = 0, events = 0;  // --trigger: events recorded (a trigger during one extends it)
  std::uint64_t pre_dropped = 0;           // left out of the --pre window by --trigger-buffer

 private:
  struct Finished {
    fs::path path;
    std::uint64_t bytes;
    std::chrono::steady_clock::time_point finished;
  };

  fs::path next_path() const { return next_path_of(files); }
  // FILE_<run's start, UTC>_<index>.mcap: a restarted recorder's files never take an earlier run's
  // names, and the names sort by time (runs by their start, a run's files by their zero-padded index).
  fs::path next_path_of(std::size_t index) const {
    if (!numbered_) return options_.out;
    fs::path path = options_.out;
    path.replace_filename(fmt::format("{}_{}_{:06}{}", options_.out.stem().string(), run_stamp_, index,
                                      options_.out.extension().string()));
    return path;
  }

  // "20261202T150102.123Z": the run's start, to the millisecond (two starts in one millisecond
  // would meet O_EXCL: "will not overwrite").
  static std::string run_stamp() {
    const auto now = std::chrono::system_clock::now();
    const std::time_t seconds = std::chrono::system_clock::to_time_t(now);
    std::tm utc{};
    ::gmtime_r(&seconds, &utc);
    const auto ms =
        std::chrono::duration_cast<std::chrono::milliseconds>(now.time_since_epoch()).count() % 1000;
    return fmt::format("{:04}{:02}{:02}T{:02}{:02}{:02}.{:03}Z", utc.tm_year + 1900, utc.tm_mon + 1,
                       utc.tm_mday, utc.tm_hour, utc.tm_min, utc.tm_sec, ms);
  }

  // Whether `name` is a file of this set: FILE_<stamp>_<index>.mcap, or FILE_<index>.mcap as rsg
  // before 0.2 named them. Anything else in the directory is not the recorder's to remove.
  bool of_this_set(const std::string& name) const {
    const std::string stem = options_.out.stem().string() + "_";
    const std::string extension = options_.out.extension().string();
    if (!name.starts_with(stem) || !name.ends_with(extension) ||
        name.size() <= stem.size() + extension.size())
      return false;
    const std::string middle = name.substr(stem.size(), name.size() - stem.size() - extension.size());
    const auto digits = [](std::string_view text) {
      return !text.empty() &&
             std::all_of(text.begin(), text.end(), [](char c) { return c >= '0' && c <= '9'; });
    };
    if (digits(middle)) return true;  // the older names
    // 20261202T150102.123Z_000000
    return middle.size() == 27 && digits(middle.substr(0, 8)) && middle[8] == 'T' &&
           digits(middle.substr(9, 6)) && middle[15] == '.' && digits(middle.substr(16, 3)) &&
           middle[19] == 'Z' && middle[20] == '_' && digits(middle.substr(21));
  }

  // Retention counts every file of the set, an earlier run's too (a recorder restarted by its
  // supervisor would otherwise leave its predecessors' files for ever): they are taken as finished,
  // oldest first (by name: the older names first, by index; then by run and index), before this run
  // writes any.
  void adopt_earlier_files() {
    const fs::path dir = options_.out.parent_path().empty() ? fs::path(".") : options_.out.parent_path();
    std::vector<std::pair<std::pair<int, std::string>, fs::path>> found;
    std::error_code error;
    for (const auto& entry : fs::directory_iterator(dir, error)) {
      const std::string name = entry.path().filename().string();
      std::error_code type_error;
      if (!entry.is_regular_file(type_error) || entry.is_symlink(type_error) || !of_this_set(name)) continue;
      const std::string middle = name.substr(options_.out.stem().string().size() + 1);
      const bool older_name = middle.find('T') == std::string::npos;
      // The older names by their number (run_2 before run_10), zero-padded to sort as text.
      found.push_back(
          {{older_name ? 0 : 1, older_name ? fmt::format("{:0>20}", middle) : name}, entry.path()});
    }
    if (error) throw rsg::mcap::WriteError("cannot list " + dir.string() + ": " + error.message());
    std::sort(found.begin(), found.end());
    const auto steady_now = std::chrono::steady_clock::now();
    const auto file_now = fs::file_time_type::clock::now();
    for (const auto& [order, path] : found) {
      std::error_code stat_error;
      const std::uintmax_t bytes = fs::file_size(path, stat_error);
      const auto written = fs::last_write_time(path, stat_error);
      if (stat_error) continue;  // gone meanwhile
      finished_.push_back(
          {path, static_cast<std::uint64_t>(bytes),
           steady_now - std::chrono::duration_cast<std::chrono::steady_clock::duration>(file_now - written)});
    }
    if (!found.empty())
      spdlog::info(
          "{} earlier {} of {} counted by retention", found.size(), found.size() == 1 ? "file" : "files",
          (dir / (options_.out.stem().string() + "_*" + options_.out.extension().string())).string());
    apply_retention();
  }

  // The bytes an event file may reach: --event-max-size, and at most half of --max-size, so that
  // retention keeps a closed event beside the next one.
  static std::uint64_t event_bytes_bound(const Options& options) {
    double mb = options.event_max_mb;
    if (options.max_mb > 0) mb = std::min(mb, options.max_mb / 2);
    return static_cast<std::uint64_t>(mb * 1e6);
  }

  void open() {
    const fs::path path = next_path();
    writer_.emplace(path, rsg::mcap::WriterOptions{.profile = std::string(rsg::app::header_profile(profile_)),
                                                   .library = "rsg_record",
                                                   .chunk_bytes = options_.chunk_bytes,
                                                   .sync = options_.fsync,
                                                   .exclusive = true});
    const auto channels = rsg::app::add_channels(*writer_, profile_, options_.topic, options_.status_topic);
    if (options_.triggered() &&
        (channels.robot_state != channels_.robot_state || channels.status != channels_.status))
      throw std::logic_error(
          "rsg_record: a file's channel ids differ from those of the samples taken before it");
    channels_ = channels;
    ++files;
    if (split_bytes_ != 0) spdlog::info("writing {}", path.string());
  }

  // What ends the current event: its --post, or its own length bound.
  std::string_view end_bound() const {
    return event_end_ == event_start_ + event_max_ns_ ? "--event-max-duration" : "";
  }

  /// `bound`: why the event was cut short ("" when it ended by --post).
  void finish_event(std::string_view bound) {
    const fs::path path = next_path_of(files - 1);
    const std::uint64_t before = messages;
    finish_file(false);
    if (bound.empty())
      spdlog::info("event {} recorded: {} ({} messages)", events - 1, path.string(), messages - before);
    else
      spdlog::warn("event {} closed at {}: {} ({} messages); a trigger after this starts a new event",
                   events - 1, bound, path.string(), messages - before);
  }

  /// `last`: no file follows (the recording ends), so retention keeps no room for one.
  void finish_file(bool last) {
    writer_->close();
    add_totals();
    if (numbered_)
      finished_.push_back(
          {next_path_of(files - 1), writer_->totals().file_bytes, std::chrono::steady_clock::now()});
    writer_.reset();
    apply_retention(last);
  }

  /// --max-files, --max-size, --max-age: removes the oldest finished files until the rest (and the
  /// file being written, or the next one) are within every limit. Finished files only: a file
  /// being written is never removed.
  void apply_retention(bool last = false) {
    const auto now = std::chrono::steady_clock::now();
    std::uint64_t bytes = 0;
    for (const Finished& file : finished_) bytes += file.bytes;
    // Room for the next file: what is being written, or at least one --split-size.
    const std::uint64_t next_bytes =
        last ? 0 : std::max(split_bytes_, writer_ ? writer_->totals().file_bytes : 0);
    const std::size_t next_files = last ? 0 : 1;
    const auto max_bytes = static_cast<std::uint64_t>(options_.max_mb * 1e6);
    const auto max_age = std::chrono::duration<double>(options_.max_age_s);
    // --trigger: the newest event is never removed, whatever the limits: what an attack (or an
    // incident) left is the file an operator needs.
    const std::size_t keep = options_.triggered() ? 1 : 0;
    while (finished_.size() > keep) {
      const Finished& oldest = finished_.front();
      const char* why = nullptr;
      if (options_.max_files != 0 && finished_.size() + next_files > options_.max_files)
        why = "--max-files";
      else if (max_bytes != 0 && bytes + next_bytes > max_bytes)
        why = "--max-size";
      else if (options_.max_age_s > 0 && now - oldest.finished > max_age)
        why = "--max-age";
      if (why == nullptr) return;
      std::error_code error;
      if (!fs::remove(oldest.path, error) && error)
        spdlog::warn("cannot remove {} ({}): {}", oldest.path.string(), why, error.message());
      else
        spdlog::info("removed {} ({})", oldest.path.string(), why);
      bytes -= oldest.bytes;
      ++removed;
      finished_.pop_front();
    }
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

  // Log time: when DDS received the sample (not when it was taken).
  static std::uint64_t log_time_of(const fdds::SampleInfo& info) {
    const std::int64_t reception_time = info.reception_timestamp.to_ns();
    return reception_time > 0 ? static_cast<std::uint64_t>(reception_time) : now_ns();
  }

  void add(std::uint16_t channel, bool contiguous, std::span<const std::uint8_t> payload,
           const fdds::SampleInfo& info) {
    // Publish time: when the gateway wrote it, the robot's frame timing that rsg_replay reproduces.
    const std::uint64_t log_time = log_time_of(info);
    const std::int64_t source_time = info.source_timestamp.to_ns();
    const std::uint64_t publish_time = source_time > 0 ? static_cast<std::uint64_t>(source_time) : log_time;
    const auto& guid = info.sample_identity.writer_guid();
    rsg::app::PublicationOrder::WriterId writer{};
    std::copy(std::begin(guid.guidPrefix.value), std::end(guid.guidPrefix.value), writer.begin());
    std::copy(std::begin(guid.entityId.value), std::end(guid.entityId.value),
              writer.begin() + sizeof(guid.guidPrefix.value));
    order_.add(writer, contiguous, payload,
               {.channel = channel,
                .sequence = static_cast<std::uint64_t>(info.sample_identity.sequence_number().to64long()),
                .log_time = log_time,
                .publish_time = publish_time,
                .payload = {}});
  }

  void write(const rsg::app::PublicationOrder::Sample& sample) {
    std::uint64_t log_time = sample.log_time;
    if (log_time < last_log_time_) {
      log_time = last_log_time_;
      ++raised;
    }
    last_log_time_ = log_time;
    if (sample.channel == channels_.robot_state) ++states_written;
    if (options_.triggered()) {
      if (writer_ && log_time > event_end_) finish_event(end_bound());
      if (writer_) write_to_file(sample, log_time);
      if (writer_ && writer_->totals().file_bytes >= event_max_bytes_) finish_event("--event-max-size");
      // Kept during an event too: an event soon after this one gets its whole --pre window as well.
      keep_for_an_event(sample, log_time);
      return;
    }
    // After a split the next file is opened by the next message, so that none is left empty.
    if (!writer_) open();
    write_to_file(sample, log_time);
    if (split_bytes_ != 0 && writer_->totals().file_bytes >= split_bytes_) finish_file(false);
  }

  void write_to_file(const rsg::app::PublicationOrder::Sample& sample, std::uint64_t log_time) {
    // The DDS sequence number (its low 32 bits: MCAP's field) lets a reader of the file see gaps.
    writer_->write(sample.channel, static_cast<std::uint32_t>(sample.sequence), log_time, sample.publish_time,
                   sample.payload);
  }

  /// The --pre window: the samples of the last --pre seconds, within --trigger-buffer bytes (the
  /// oldest go first when a fast stream would need more).
  void keep_for_an_event(const rsg::app::PublicationOrder::Sample& sample, std::uint64_t log_time) {
    pre_.push_back(sample);
    pre_.back().log_time = log_time;
    pre_bytes_ += footprint(sample);
    while (!pre_.empty() && pre_.front().log_time + pre_ns_ < log_time) drop_oldest();
    bool over = false;
    while (!pre_.empty() && pre_bytes_ > buffer_bytes_) {
      drop_oldest();
      ++pre_dropped;
      over = true;
    }
    if (over && !warned_buffer_) {
      warned_buffer_ = true;
      spdlog::warn(
          "--trigger-buffer {:g} MB holds {:.2f} s of this stream, less than --pre {:g}: an event "
          "file starts that long before its event",
          options_.trigger_buffer_mb,
          pre_.empty() ? 0.0 : static_cast<double>(log_time - pre_.front().log_time) / 1e9, options_.pre_s);
    }
  }
  static std::uint64_t footprint(const rsg::app::PublicationOrder::Sample& sample) {
    return sizeof(sample) + sample.payload.capacity();
  }
  void drop_oldest() {
    pre_bytes_ -= footprint(pre_.front());
    pre_.pop_front();
  }

  const Options& options_;
  rsg::app::Profile profile_;
  std::uint64_t split_bytes_;
  std::optional<rsg::mcap::Writer> writer_;
  rsg::app::Channels channels_;
  rsg::app::CdrSerializer serializer_;
  bool numbered_;  // FILE_0.mcap, FILE_1.mcap, ... (--split-size, --trigger)
  std::uint64_t pre_ns_, post_ns_, buffer_bytes_;
  std::uint64_t event_max_ns_, event_max_bytes_;
  std::string run_stamp_;  // the run's start: its files' names (next_path_of)
  rsg::app::PublicationOrder order_;
  std::uint64_t last_log_time_ = 0;
  std::deque<Finished> finished_;  // with --split-size or --trigger, oldest first, not yet removed
  std::deque<rsg::app::PublicationOrder::Sample> pre_;  // --trigger: the --pre window, oldest first
  std::uint64_t pre_bytes_ = 0;
  bool warned_buffer_ = false;
  std::uint64_t event_start_ = 0;         // --trigger: the log time of the current event's first trigger
  std::uint64_t event_end_ = 0;           // --trigger: the log time up to which the current event records
  std::optional<bool> link_up_;           // --trigger link-down: as the last status sample said
  std::optional<std::uint64_t> invalid_;  // --trigger invalid: the last status sample's total
};

void add_options(CLI::App& app, Options& options) {
  app.add_option("--out", options.out, "MCAP file to write")->required()->check(rsg::app::writable_file());
  rsg::app::add_monitor_options(app, options, "records none");
  app.add_option("--profile", options.profile,
                 "MCAP flavour: omgidl (default: rsg's IDL, for Foxglove) or ros2 (ros2msg schemas and the "
                 "channel metadata rosbag2 expects)");
  app.add_option("--duration", options.duration_s,
                 "Stop after this many seconds (default: until SIGINT/SIGTERM)")
      ->check(rsg::app::non_negative_number());
  app.add_option(
         "--recover", options.recover,
         "Do not record: write what FILE (a recording whose recorder was killed) holds up to its last "
         "whole chunk to --out as a finished, indexed file, and exit")
      ->check(CLI::ExistingFile);
  auto* split =
      app.add_option("--split-size", options.split_mb,
                     "Start a new file when one reaches this many MB: FILE_<run's start, UTC>_000000.mcap, "
                     "..._000001.mcap, ... (names that sort by time; a restarted recorder never overwrites "
                     "an earlier run's files)")
          ->check(rsg::app::non_negative_number());
  // Record only around events, as the gateway's flight recorder keeps its datagrams: a recorder left
  // running writes nothing until something happens.
  auto* trigger =
      app.add_option("--trigger", options.triggers,
                     "Record only around events: signal (SIGUSR1), link-down (the gateway's status says "
                     "its link went down), invalid (it counted invalid frames since its previous status); "
                     "each event gets a file FILE_<run's start, UTC>_000000.mcap, ... with --pre "
                     "seconds before it and --post after (an event meanwhile extends it, within "
                     "--event-max-duration and --event-max-size)")
          ->check(CLI::IsMember({"signal", "link-down", "invalid"}))
          ->delimiter(',')
          ->excludes(split);
  app.add_option("--pre", options.pre_s, "With --trigger: seconds recorded before an event")
      ->check(rsg::app::non_negative_number())
      ->capture_default_str()
      ->needs(trigger);
  app.add_option("--post", options.post_s, "With --trigger: seconds recorded after an event")
      ->check(rsg::app::non_negative_number())
      ->capture_default_str()
      ->needs(trigger);
  app.add_option("--event-max-duration", options.event_max_s,
                 "With --trigger: an event that triggers keep extending is closed (and kept) this many "
                 "seconds after its first trigger; a trigger after that starts a new event")
      ->check(rsg::app::positive_number())
      ->capture_default_str()
      ->needs(trigger);
  app.add_option("--event-max-size", options.event_max_mb,
                 "With --trigger: an event's file is closed (and kept) when it reaches this many MB, or half "
                 "of --max-size if that is less; a trigger after that starts a new event")
      ->check(rsg::app::positive_number())
      ->capture_default_str()
      ->needs(trigger);
  app.add_option("--trigger-buffer", options.trigger_buffer_mb,
                 "With --trigger: MB of memory the --pre window may take (a faster stream keeps less than "
                 "--pre seconds, with a warning)")
      ->check(rsg::app::number_in(0.1, 4096.0))
      ->capture_default_str()
      ->needs(trigger);
  // Retention, as rosbag2 users know it from storage limits: a recorder left running keeps the
  // newest files within the limits instead of filling the disk (checked in main: with --split-size
  // or --trigger).
  app.add_option(
         "--max-files", options.max_files,
         "With --split-size or --trigger: keep at most this many files of FILE_* (the one being written "
         "included, an earlier run's counted too), removing the oldest; with --trigger the newest event is "
         "never removed")
      ->check(CLI::Range(std::size_t{2}, std::numeric_limits<std::size_t>::max()));
  app.add_option(
         "--max-size", options.max_mb,
         "With --split-size or --trigger: keep the files within about this many MB together, removing "
         "the oldest (room is kept for one more --split-size file)")
      ->check(rsg::app::positive_number());
  app.add_option("--max-age", options.max_age_s,
                 "With --split-size or --trigger: remove a finished file this many seconds after it was "
                 "finished")
      ->check(rsg::app::positive_number());
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
  rsg::app::MatchedWriters matched_writers(options.topic, writers, options.domain);
  rsg::RobotState state;
  rsg::GatewayStatus status;
  fdds::SampleInfo info;
  int exit_code = kExitOk;
  // DDS counts as lost, too, the samples of the writer's history it gave up on while the reader
  // joined (from before the recording's first sample): only what it counts after that is a loss.
  std::optional<std::int32_t> lost_before_first;
  fdds::SampleLostStatus lost;
  const auto take_what_was_received = [&] {
    while (readers.state().take_next_sample(&state, &info) == rsg::dds::kOk) {
      if (!info.valid_data) continue;
      matched_writers.on_sample();
      recording.add_state(state, info);
    }
    while (readers.status() != nullptr && readers.status()->take_next_sample(&status, &info) == rsg::dds::kOk)
      if (info.valid_data) recording.add_status(status, info);
  };
  const auto note_first_written = [&] {
    if (lost_before_first || recording.states_written == 0) return;
    readers.state().get_sample_lost_status(lost);
    lost_before_first = lost.total_count;
  };
  const bool trigger_on_signal = options.trigger_on("signal");
  try {
    while (!readers.stop_requested() &&
           (options.duration_s == 0 || std::chrono::steady_clock::now() - start < duration)) {
      readers.wait(kBatchPeriod);
      matched_writers.update(readers.state());
      take_what_was_received();
      if (trigger_on_signal && TriggerSignal::take()) recording.trigger(now_ns(), "SIGUSR1");
      recording.write_due(now_ns());
      note_first_written();
      recording.tick();
    }
    // A slow disk (--fsync, a busy host) can leave the recorder seconds behind DDS: what the reader
    // history already holds at SIGTERM was received and belongs in the file.
    take_what_was_received();
    recording.close();
    note_first_written();
  } catch (const rsg::mcap::WriteError& error) {
    spdlog::error("{}", error.what());
    recording.count_failed_file();
    exit_code = kExitFailure;
  }

  readers.state().get_sample_lost_status(lost);
  const auto counts = recording.state_counts();
  const double ratio = recording.compressed == 0 ? 0
                                                 : static_cast<double>(recording.uncompressed) /
                                                       static_cast<double>(recording.compressed);
  std::string summary = fmt::format(
      "{} messages in {} chunks, {} {}, {} bytes; compression ratio {:g}; received {} states, {} statuses; "
      "dropped {} (sequence gaps), {} (lost in DDS)",
      recording.messages, recording.chunks, recording.files, recording.files == 1 ? "file" : "files",
      recording.file_bytes, ratio, recording.states, recording.statuses, counts.gaps,
      lost_before_first ? lost.total_count - *lost_before_first : 0);
  if (counts.late > 0)
    summary += fmt::format("; {} of the dropped arrived after a later state was written", counts.late);
  if (counts.before_start > 0)
    summary += fmt::format("; {} states from before the first recorded one arrived late, left out",
                           counts.before_start);
  if (recording.raised > 0)
    summary += fmt::format("; {} log times raised to keep their order", recording.raised);
  if (options.triggered())
    summary += fmt::format("; {} {} ({} {})", recording.events, recording.events == 1 ? "event" : "events",
                           recording.triggers, recording.triggers == 1 ? "trigger" : "triggers");
  if (recording.pre_dropped > 0)
    summary +=
        fmt::format("; {} samples of the --pre window left out (--trigger-buffer)", recording.pre_dropped);
  if (recording.removed > 0)
    summary += fmt::format("; {} oldest {} removed (retention)", recording.removed,
                           recording.removed == 1 ? "file" : "files");
  if (options.fsync)
    summary +=
        fmt::format("; {} fsyncs in {:g} ms", recording.syncs, static_cast<double>(recording.sync_ns) / 1e6);
  spdlog::info("{}", summary);
  if (!matched_writers.ever_matched()) {
    // An empty file and exit 0 would look like a recording of an idle robot.
    matched_writers.explain_if_unmatched(readers.state());
    spdlog::error("no writer of '{}' matched in {:.1f} s (see the warnings above): {}", options.topic,
                  std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(),
                  recording.written());
    return kExitFailure;
  }
  return exit_code;
}

}  // namespace

int main(int argc, char** argv) {
  rsg::app::init_logging("rsg_record");
  StopOnSignal::block_stop_signals();  // before Fast DDS starts threads (stop_on_signal.hpp)
  CLI::App app{"Records RobotState and GatewayStatus samples into an MCAP file.", "rsg_record"};
  app.footer(
      "With --trigger signal, SIGUSR1 records an event. "
      "Exit status: 0 after --duration or on SIGINT/SIGTERM (the file finished), 1 when the file cannot be "
      "written (what was recorded stays readable), DDS fails or no writer of the topic matched, 2 usage "
      "error. --recover: 0 when FILE read "
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
    if ((options.max_files != 0 || options.max_mb > 0 || options.max_age_s > 0) && options.split_mb == 0 &&
        !options.triggered())
      throw rsg::InputError(fmt::format("{} needs --split-size or --trigger: one file has nothing to remove",
                                        options.max_files != 0 ? "--max-files"
                                        : options.max_mb > 0   ? "--max-size"
                                                               : "--max-age"));
    for (const char* status_trigger : {"link-down", "invalid"})
      if (options.trigger_on(status_trigger) && options.status_topic.empty())
        throw rsg::InputError(fmt::format(
            "--trigger {} reads the gateway's status: --status-topic must not be empty", status_trigger));
    // Before DDS starts its threads (StopOnSignal::block_stop_signals() says why).
    if (options.trigger_on("signal")) TriggerSignal::block();
    if (options.max_mb > 0 && options.max_mb < 2 * options.split_mb)
      throw rsg::InputError(
          fmt::format("--max-size {:g} keeps no finished file of --split-size {:g}: give at least {:g}",
                      options.max_mb, options.split_mb, 2 * options.split_mb));
    options.load_profiles();
    return run(options, *profile);
  });
}
