// rsg_echo: subscribes to a RobotState topic, whole or through a group view, and prints what
// arrives: one canonical JSON line per sample (--json), or a live table for a terminal.
//
// Exit status: 0 after --count samples or on SIGINT/SIGTERM, 1 on --timeout (no sample for that
// many seconds, counted from start-up and from each sample) or a DDS failure, 2 on usage errors
// (including unknown or malformed profiles).
#include <RobotState.h>
#include <pthread.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <csignal>
#include <cstdio>
#include <fastdds/dds/core/LoanableSequence.hpp>
#include <fastdds/dds/core/condition/GuardCondition.hpp>
#include <fastdds/dds/core/condition/WaitSet.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <iostream>
#include <optional>
#include <stop_token>
#include <thread>

#include "app/dds_options.hpp"
#include "app/discovery_cli.hpp"
#include "app/matched_writers.hpp"
#include "app/number_checks.hpp"
#include "app/stop_on_signal.hpp"
#include "app/tool_main.hpp"
#include "rsg/dds/fastdds.hpp"
#include "rsg/dds/participant.hpp"
#include "rsg/dds/profiles.hpp"
#include "rsg/dds/robot_state.hpp"
#include "rsg/dds/ros2.hpp"
#include "rsg/dds/views.hpp"
#include "rsg/dds/writer_directory.hpp"
#include "rsg/error.hpp"
#include "rsg/wire/json.hpp"
#include "rsg/wire/selection.hpp"
#include "tools/echo/live_table.hpp"

namespace {

namespace fdds = eprosima::fastdds::dds;
using rsg::tools::echo::Clock;

using namespace rsg::app;  // the main skeleton and the exit statuses

// The table is redrawn at most this often, and the timeout checked as often.
constexpr auto kRefreshPeriod = std::chrono::milliseconds(100);

struct Options {
  int domain = 0;
  std::string topic = "robot_state";
  bool ros2 = false;  // the ROS 2 DDS names that rsg_gateway --ros2 writes
  std::string ros2_namespace;
  std::vector<std::string> partitions;
  std::string view_profile;
  std::string groups;
  std::string qos_profile;  // empty: reader_logger with --json, reader_realtime otherwise
  bool json = false;
  std::uint64_t count = 0;  // 0: no limit
  double timeout_seconds = 0;
  std::vector<std::string> profiles;  // empty: rsg::dds::default_profiles_dir()
  std::string participant_profile = "rsg_participant";
  rsg::dds::DiscoveryOptions discovery;
};

using rsg::app::StopOnSignal;

const char* policy_name(fdds::QosPolicyId_t id) {
  switch (id) {
    case fdds::DURABILITY_QOS_POLICY_ID:
      return "DURABILITY";
    case fdds::DEADLINE_QOS_POLICY_ID:
      return "DEADLINE";
    case fdds::LIVELINESS_QOS_POLICY_ID:
      return "LIVELINESS";
    case fdds::RELIABILITY_QOS_POLICY_ID:
      return "RELIABILITY";
    case fdds::OWNERSHIP_QOS_POLICY_ID:
      return "OWNERSHIP";
    case fdds::DATAREPRESENTATION_QOS_POLICY_ID:
      return "DATA_REPRESENTATION";
    default:
      return "another policy";
  }
}

/// Prints samples one way or the other; both see every sample taken, in order.
class SampleSink {
 public:
  SampleSink(bool json, std::string header) : json_(json), header_(std::move(header)) {}

  void add(const rsg::wire::StateValues& values, Clock::time_point now) {
    if (json_) {
      rsg::wire::append_canonical_json(values, pending_);
      pending_ += '\n';
    } else {
      stats_.add(values, now);
    }
  }

  /// JSON: writes what is pending (once per batch, so a 1 kHz stream is not 1000 syscalls a
  /// second, and a consumer never waits longer than a batch). Table: redraws when it is due.
  void flush(Clock::time_point now, bool force_table = false) {
    if (json_) {
      std::fwrite(pending_.data(), 1, pending_.size(), stdout);
      std::fflush(stdout);
      pending_.clear();
      return;
    }
    if (!force_table && now < next_draw_) return;
    next_draw_ = now + kRefreshPeriod;
    const std::string table = rsg::tools::echo::render_table(header_, stats_, now);
    if (interactive_) {
      terminal_.draw(table);
    } else if (force_table || now >= next_log_) {  // a log file gets one table a second
      next_log_ = now + std::chrono::seconds(1);
      std::fwrite(table.data(), 1, table.size(), stdout);
      std::fflush(stdout);
    }
  }

 private:
  bool json_;
  std::string header_;
  std::string pending_;
  rsg::tools::echo::StreamStats stats_;
  rsg::tools::echo::TerminalTable terminal_;
  bool interactive_ = ::isatty(STDOUT_FILENO) != 0;
  Clock::time_point next_draw_;
  Clock::time_point next_log_;
};

void add_options(CLI::App& app, Options& options) {
  rsg::app::add_log_level_option(app);
  app.add_option("--domain", options.domain, "DDS domain id")
      ->check(CLI::Range(0, 232))
      ->capture_default_str();
  app.add_option("--topic", options.topic, "RobotState topic")
      ->check(rsg::app::dds_name(false))
      ->capture_default_str();
  app.add_option("--partition", options.partitions, "DDS partition (repeatable; default: none)")
      ->check(rsg::app::dds_name(true));
  app.add_flag(
      "--ros2", options.ros2,
      "Read what rsg_gateway --ros2 writes: topic rt/<ns>/<topic>, type rsg_msgs::msg::dds_::RobotState_");
  app.add_option("--ros2-namespace", options.ros2_namespace, "ROS 2 namespace with --ros2, e.g. /robot1")
      ->check([](const std::string& ns) { return rsg::dds::parse_ros2_namespace(ns).error(); });
  auto* view = app.add_option("--view", options.view_profile,
                              "View profile, e.g. view_joints: only samples carrying its groups");
  auto* groups = app.add_option("--groups", options.groups,
                                "Only samples carrying all these groups, e.g. 2,3 (an ad-hoc view)");
  view->excludes(groups);
  app.add_option("--qos", options.qos_profile,
                 "Reader QoS profile (default: reader_logger with --json, reader_realtime otherwise)");
  app.add_flag("--json", options.json,
               "One canonical JSON line per sample (as rsg_frame decode prints the frame); never "
               "drops samples at 1 kHz with the default reliable reader");
  app.add_option("--count", options.count, "Exit 0 after this many samples (default: no limit)");
  app.add_option("--timeout", options.timeout_seconds,
                 "Exit 1 when no sample arrives for this many seconds, from start-up or the last "
                 "sample (default: wait forever)")
      ->check(rsg::app::non_negative_number());
  rsg::app::add_profile_options(app, options.profiles, options.participant_profile,
                                "XML participant profile, e.g. rsg_secure_reader under DDS Security");
  rsg::app::add_discovery_options(app, options.discovery);
}

/// What the reader reads: a view, or the whole topic.
std::optional<rsg::dds::View> requested_view(const Options& options, const fdds::Subscriber& subscriber) {
  if (!options.view_profile.empty()) return rsg::dds::load_view(subscriber, options.view_profile);
  if (options.groups.empty()) return std::nullopt;
  const rsg::wire::Parsed<std::uint8_t> mask = rsg::wire::parse_group_mask(options.groups);
  if (!mask) throw rsg::dds::ViewError("--groups: " + mask.error());
  return rsg::dds::group_view(*mask);
}

int run(const Options& options) {
  rsg::dds::WriterDirectory writers;  // what discovery shows, should no writer match
  rsg::dds::Participant participant(options.domain, options.participant_profile, options.discovery,
                                    writers.listener());
  const std::string topic_name =
      options.ros2 ? rsg::dds::ros2_topic_name(options.ros2_namespace, options.topic) : options.topic;
  fdds::Topic& topic = *participant.robot_state_topic(
      topic_name, options.ros2 ? std::string(rsg::dds::kRos2RobotStateType) : "");
  fdds::Subscriber& subscriber = *participant.subscriber(options.partitions);

  const std::string qos_profile = !options.qos_profile.empty() ? options.qos_profile
                                  : options.json               ? rsg::dds::kLoggerReaderProfile
                                                               : rsg::dds::kRealtimeReaderProfile;
  const fdds::DataReaderQos qos = rsg::dds::load_reader_qos(subscriber, qos_profile);
  std::optional<rsg::dds::ViewReader> view_reader;
  fdds::DataReader* reader = nullptr;  // owned by view_reader, or by the participant
  if (auto view = requested_view(options, subscriber)) {
    view_reader.emplace(subscriber, topic, std::move(*view), qos);
    reader = view_reader->get();
  } else {
    reader = subscriber.create_datareader(&topic, qos);
    if (reader == nullptr) throw rsg::EnvironmentError("cannot create a reader on '" + topic_name + "'");
  }
  const std::string read_topic = view_reader ? view_reader->filtered_topic()->get_name() : topic_name;

  std::string header = "rsg_echo  " + read_topic + "  domain " + std::to_string(options.domain);
  for (const auto& partition : options.partitions) header += "  partition " + partition;
  header += "  qos " + qos_profile;
  SampleSink sink(options.json, header);

  fdds::GuardCondition stop;
  StopOnSignal stop_on_signal([&stop] { stop.set_trigger_value(true); });
  fdds::StatusCondition& reader_condition = reader->get_statuscondition();
  reader_condition.set_enabled_statuses(fdds::StatusMask::data_available()
                                        << fdds::StatusMask::requested_incompatible_qos()
                                        << fdds::StatusMask::subscription_matched());
  rsg::app::MatchedWriters matched_writers(read_topic, writers, options.domain);
  fdds::WaitSet waitset;
  waitset.attach_condition(reader_condition);
  waitset.attach_condition(stop);

  const auto timeout =
      std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(options.timeout_seconds));
  auto last_sample = Clock::now();
  std::uint64_t received = 0;
  FASTDDS_SEQUENCE(RobotStateSeq, rsg::RobotState);
  RobotStateSeq samples;
  fdds::SampleInfoSeq infos;
  rsg::wire::StateValues values;

  while (true) {
    fdds::ConditionSeq triggered;
    waitset.wait(
        triggered,
        rsg::dds::Duration(0, static_cast<std::uint32_t>(std::chrono::nanoseconds(kRefreshPeriod).count())));
    matched_writers.update(*reader);
    const auto now = Clock::now();
    if (stop.get_trigger_value()) {
      sink.flush(now, /*force_table=*/true);
      return kExitOk;
    }

    fdds::RequestedIncompatibleQosStatus incompatible;
    if (reader->get_requested_incompatible_qos_status(incompatible) == rsg::dds::kOk &&
        incompatible.total_count_change > 0)
      spdlog::warn(
          "a writer of '{}' does not match reader profile '{}': its {} offer is below this reader's "
          "request",
          topic_name, qos_profile, policy_name(incompatible.last_policy_id));

    // Take everything available: at 1 kHz a wake-up finds several samples.
    bool done = false;
    while (!done && reader->take(samples, infos) == rsg::dds::kOk) {
      for (fdds::LoanableCollection::size_type i = 0; i < samples.length() && !done; ++i) {
        if (!infos[i].valid_data) continue;
        rsg::dds::to_values(samples[i], values);
        // A data-sharing loan points into the writer's history, which the writer may have reused
        // for a newer sample before or while it was copied; such a copy is no sample at all.
        if (!reader->is_sample_valid(&samples[i], &infos[i])) continue;
        sink.add(values, now);
        matched_writers.on_sample();
        last_sample = now;
        done = options.count != 0 && ++received == options.count;
      }
      reader->return_loan(samples, infos);
    }
    sink.flush(now, done);
    if (done) return kExitOk;
    if (options.timeout_seconds > 0 && now - last_sample >= timeout) {
      matched_writers.explain_if_unmatched(*reader);
      spdlog::error("no sample on '{}' for {} s", read_topic, options.timeout_seconds);
      return kExitFailure;
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  rsg::app::init_logging("rsg_echo");
  StopOnSignal::block_stop_signals();  // before Fast DDS starts threads (stop_on_signal.hpp)
  CLI::App app{"Prints the RobotState samples of a topic, or of a group view of it.", "rsg_echo"};
  app.footer(
      "Views: view_poses (group 0), view_load_and_elbow (1), view_joints (2), view_contact (3), "
      "view_cartesian_motor (4), view_status (5), view_kinematics (0,2), view_forces (2,3), view_full "
      "(0..5); a sample passes when it carries all the view's groups.\n"
      "Exit status: 0 after --count samples or on SIGINT/SIGTERM, 1 on --timeout or a DDS failure, 2 "
      "usage error (including an unknown or malformed profile).");
  Options options;
  add_options(app, options);
  return run_main(app, argc, argv, [&] {
    rsg::app::load_profile_options(options.profiles, options.participant_profile);
    rsg::app::check_profiles({{"--view", rsg::app::NamedProfile::Kind::kDataReader, options.view_profile},
                              {"--qos", rsg::app::NamedProfile::Kind::kDataReader, options.qos_profile}});
    return run(options);
  });
}
