// rsg_secure_probe: one end of the DDS Security tests, driven by security_test.py.
//
//   rsg_secure_probe publish|subscribe --profiles FILE [--profiles FILE...] --profile NAME
//                                      --domain ID [--partition NAME] [--samples N] [--seed S]
//                                      [--marker]
//
// Both ends derive the same samples from --seed, so the subscriber checks each one bit for bit
// against its own copy and the values travel over DDS only. The publisher writes them once, at
// start, reliable and transient-local, so that a reader matched later still gets every one.
// --marker fills every double with kMarker, a pattern the test then looks for in the packets.
//
// What happens is reported on stdout, one JSON object per line:
//   {"event":"ready","participant":P,"endpoint_created":B,"marker":HEX}
//       set up; P is our GUID prefix, B false when Fast DDS refused to create our writer or
//       reader (access control), HEX the marker's bytes as serialized
//   {"event":"discovery","participant":P,"status":S}  S: discovered, changed, removed, dropped
//   {"event":"authentication","participant":P,"status":"authorized"|"unauthorized"}
//   {"event":"matched"|"unmatched","participant":P}   a remote endpoint (un)matched ours
//   {"event":"sample","index":I,"exact":B}            sample I arrived, bit-identical or not
// Fast DDS's own log goes to stderr. The probe runs until its standard input closes: the test
// holds that pipe, so probes never outlive a test that crashed.
#include <RobotState.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <array>
#include <bit>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/domain/DomainParticipantListener.hpp>
#include <fastdds/dds/log/Log.hpp>
#include <fastdds/dds/log/StdoutErrConsumer.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/DataWriterListener.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <iostream>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "dds/internal/fastdds_compat.hpp"
#include "rsg/dds/participant.hpp"
#include "rsg/dds/profiles.hpp"
#include "rsg/dds/robot_state.hpp"
#include "rsg/wire/hex.hpp"
#include "rsg/wire/json.hpp"
#include "tests/support/random_state.hpp"

namespace rsg::security_probe {
namespace fdds = eprosima::fastdds::dds;
namespace {

namespace rtps = rsg::dds::rtps;

/// The bytes "RSG-LEAK" read as a little-endian double: finite, and unlikely to occur by chance
/// in ciphertext or in any other part of an RTPS message.
constexpr std::uint64_t kMarkerBits = 0x4B41454C2D475352;
constexpr double kMarker = std::bit_cast<double>(kMarkerBits);

struct Options {
  std::vector<std::string> profile_files;
  std::string profile;
  int domain = 0;
  std::size_t samples = 20;
  std::uint64_t seed = 1;
  bool marker = false;
  std::string partition;  ///< empty: the default partition
  std::string topic = "robot_state";
  bool wait_for_reader = false;  ///< publish: write only once a reader matched (for volatile readers)
};

std::vector<std::string> partitions(const Options& options) {
  if (options.partition.empty()) return {};
  return {options.partition};
}

/// The samples both ends agree on. With `marker`, every field is selected and every double is
/// kMarker, so that each sample carries the pattern many times over.
std::vector<wire::StateValues> make_samples(const Options& options) {
  std::vector<wire::StateValues> samples;
  std::mt19937_64 rng(options.seed);
  for (std::size_t i = 0; i < options.samples; ++i) {
    wire::StateValues values = test::random_state(rng);
    if (options.marker) {
      values.selection = wire::Selection::all();
      for (const wire::FieldInfo& field : wire::kFields)
        if (field.type == wire::ElementType::kFloat64)
          for (double& element : values.doubles(field.id())) element = kMarker;
    }
    samples.push_back(values);
  }
  return samples;
}

/// The marker as CDR puts it on the wire: Fast DDS serializes in the host's byte order, so in the
/// order it has in memory.
std::string marker_hex() {
  return wire::to_hex(std::bit_cast<std::array<std::uint8_t, sizeof kMarker>>(kMarker));
}

std::string to_string(const rtps::GuidPrefix_t& prefix) {
  std::ostringstream text;
  text << prefix;
  return text.str();
}

/// The JSON-lines report on stdout. Fast DDS calls listeners from its own threads, hence the lock:
/// each event is one whole line, flushed at once so that the test sees it immediately.
class EventLog {
 public:
  void emit(const nlohmann::ordered_json& event) {
    const std::string line = event.dump() + "\n";
    const std::lock_guard lock(mutex_);
    std::fwrite(line.data(), 1, line.size(), stdout);
    std::fflush(stdout);
  }

 private:
  std::mutex mutex_;
};

/// Reports what the participant learns about others: whom it discovered and whether their
/// identity and permissions passed the security handshake.
class ParticipantEvents : public fdds::DomainParticipantListener {
 public:
  explicit ParticipantEvents(EventLog& log) : log_(log) {}

  void on_participant_discovery(fdds::DomainParticipant*, rtps::ParticipantDiscoveryInfo&& info) override {
    using Status = rtps::ParticipantDiscoveryInfo::DISCOVERY_STATUS;
    const char* status = "ignored";
    switch (info.status) {
      case Status::DISCOVERED_PARTICIPANT:
        status = "discovered";
        break;
      case Status::CHANGED_QOS_PARTICIPANT:
        status = "changed";
        break;
      case Status::REMOVED_PARTICIPANT:
        status = "removed";
        break;
      case Status::DROPPED_PARTICIPANT:
        status = "dropped";
        break;
      default:
        break;
    }
    log_.emit({{"event", "discovery"},
               {"participant", to_string(info.info.m_guid.guidPrefix)},
               {"status", status}});
  }

  void onParticipantAuthentication(fdds::DomainParticipant*,
                                   rtps::ParticipantAuthenticationInfo&& info) override {
    const bool authorized = info.status == rtps::ParticipantAuthenticationInfo::AUTHORIZED_PARTICIPANT;
    log_.emit({{"event", "authentication"},
               {"participant", to_string(info.guid.guidPrefix)},
               {"status", authorized ? "authorized" : "unauthorized"}});
  }

 private:
  EventLog& log_;
};

void emit_match(EventLog& log, int change, const fdds::InstanceHandle_t& remote) {
  if (change == 0) return;
  log.emit({{"event", change > 0 ? "matched" : "unmatched"},
            {"participant", to_string(rtps::iHandle2GUID(remote).guidPrefix)}});
}

class WriterEvents : public fdds::DataWriterListener {
 public:
  explicit WriterEvents(EventLog& log) : log_(log) {}

  void on_publication_matched(fdds::DataWriter*, const fdds::PublicationMatchedStatus& status) override {
    emit_match(log_, status.current_count_change, status.last_subscription_handle);
  }

 private:
  EventLog& log_;
};

/// Takes every sample as it arrives and compares it with the one the publisher derived from the
/// same seed, in order: reliable transient-local delivery loses and reorders nothing.
class ReaderEvents : public fdds::DataReaderListener {
 public:
  ReaderEvents(EventLog& log, const std::vector<wire::StateValues>& expected)
      : log_(log), expected_(expected) {}

  void on_subscription_matched(fdds::DataReader*, const fdds::SubscriptionMatchedStatus& status) override {
    emit_match(log_, status.current_count_change, status.last_publication_handle);
  }

  void on_data_available(fdds::DataReader* reader) override {
    fdds::SampleInfo info;
    while (reader->take_next_sample(&sample_, &info) == rsg::dds::kOk) {
      if (!info.valid_data) continue;
      wire::StateValues received;
      dds::to_values(sample_, received);
      const bool exact = next_index_ < expected_.size() && received == expected_[next_index_];
      nlohmann::ordered_json event = {{"event", "sample"}, {"index", next_index_}, {"exact", exact}};
      if (!exact) event["received"] = nlohmann::json::parse(wire::to_canonical_json(received));
      log_.emit(event);
      ++next_index_;
    }
  }

 private:
  EventLog& log_;
  const std::vector<wire::StateValues>& expected_;
  std::size_t next_index_ = 0;
  RobotState sample_;  // reused: a RobotState is a few kilobytes
};

fdds::DataWriterQos writer_qos(fdds::Publisher& publisher, std::size_t samples) {
  fdds::DataWriterQos qos = publisher.get_default_datawriter_qos();
  qos.reliability().kind = fdds::RELIABLE_RELIABILITY_QOS;
  qos.durability().kind = fdds::TRANSIENT_LOCAL_DURABILITY_QOS;
  qos.history().kind = fdds::KEEP_LAST_HISTORY_QOS;
  qos.history().depth = static_cast<std::int32_t>(samples);
  // Same-host data-sharing would hand samples over in shared memory, bypassing the transport
  // that the tests watch; with security on Fast DDS does not use it anyway.
  qos.data_sharing().off();
  return qos;
}

/// Bounded: a reader that never comes is the test's to report, from what the reader did not get.
void wait_for_a_reader(fdds::DataWriter& writer) {
  fdds::PublicationMatchedStatus matched;
  for (int i = 0; i < 600 && matched.current_count == 0; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    writer.get_publication_matched_status(matched);
  }
}

fdds::DataReaderQos reader_qos(fdds::Subscriber& subscriber) {
  fdds::DataReaderQos qos = subscriber.get_default_datareader_qos();
  qos.reliability().kind = fdds::RELIABLE_RELIABILITY_QOS;
  qos.durability().kind = fdds::TRANSIENT_LOCAL_DURABILITY_QOS;
  qos.history().kind = fdds::KEEP_ALL_HISTORY_QOS;
  qos.data_sharing().off();
  return qos;
}

/// Enables a participant created disabled (see run), once the listener is in place: discovery and
/// authentication start on enable, so no event is missed.
void enable_with_listener(dds::Participant& participant, ParticipantEvents& listener) {
  // No status callbacks: with data_on_readers in its mask, a participant listener takes the data
  // that the readers' own listeners are waiting for. Discovery and authentication are unmasked.
  participant.get()->set_listener(&listener, fdds::StatusMask::none());
  if (participant.get()->enable() != rsg::dds::kOk)
    throw std::runtime_error("cannot enable the DDS participant");
}

void wait_for_stdin_to_close() {
  std::array<char, 256> discard{};
  while (::read(STDIN_FILENO, discard.data(), discard.size()) > 0) {
  }
}

void run(const Options& options, bool publishing) {
  for (const auto& file : options.profile_files) dds::load_profiles(file);
  // Participants start disabled; enable_with_listener enables ours.
  auto* factory = fdds::DomainParticipantFactory::get_instance();
  fdds::DomainParticipantFactoryQos factory_qos;
  factory->get_qos(factory_qos);
  factory_qos.entity_factory().autoenable_created_entities = false;
  factory->set_qos(factory_qos);

  // Listeners first: they must outlive the participant, whose threads call them until it is gone.
  const std::vector<wire::StateValues> samples = make_samples(options);
  EventLog log;
  ParticipantEvents participant_events(log);
  WriterEvents writer_events(log);
  ReaderEvents reader_events(log, samples);

  dds::Participant participant(options.domain, options.profile);
  enable_with_listener(participant, participant_events);
  fdds::Topic* topic = participant.robot_state_topic(options.topic);

  bool endpoint_created = false;
  if (publishing) {
    fdds::Publisher* publisher = participant.publisher(partitions(options));
    fdds::DataWriter* writer =
        publisher->create_datawriter(topic, writer_qos(*publisher, options.samples), &writer_events);
    if (writer != nullptr) {
      endpoint_created = true;
      if (options.wait_for_reader) wait_for_a_reader(*writer);
      RobotState sample;
      for (const wire::StateValues& values : samples) {
        dds::to_sample(values, sample);
        if (!writer->write(&sample)) throw std::runtime_error("cannot write a sample");
      }
    }
  } else {
    fdds::Subscriber* subscriber = participant.subscriber(partitions(options));
    endpoint_created =
        subscriber->create_datareader(topic, reader_qos(*subscriber), &reader_events) != nullptr;
  }
  log.emit({{"event", "ready"},
            {"participant", to_string(participant.get()->guid().guidPrefix)},
            {"endpoint_created", endpoint_created},
            {"marker", marker_hex()}});
  // A refused endpoint is an outcome to report, not a reason to leave: the participant stays in
  // the domain so that the test can check what the others make of it.
  wait_for_stdin_to_close();
}

void log_fast_dds_to_stderr() {
  using eprosima::fastdds::dds::Log;
  auto consumer = std::make_unique<eprosima::fastdds::dds::StdoutErrConsumer>();
  consumer->stderr_threshold(Log::Kind::Info);
  Log::ClearConsumers();
  Log::RegisterConsumer(std::move(consumer));
  Log::SetVerbosity(Log::Kind::Error);
}

}  // namespace
}  // namespace rsg::security_probe

int main(int argc, char** argv) {
  using namespace rsg::security_probe;
  CLI::App app("One end of the rsg DDS Security tests: publishes or checks seeded RobotState samples");
  app.require_subcommand(1);
  Options options;
  auto add_options = [&options](CLI::App& command) {
    command.add_option("--profiles", options.profile_files, "Fast DDS XML profile file(s) to load")
        ->required();
    command.add_option("--profile", options.profile, "participant profile")->required();
    command.add_option("--domain", options.domain, "DDS domain id")->required()->check(CLI::Range(0, 232));
    command.add_option("--samples", options.samples, "number of samples")->capture_default_str();
    command.add_option("--seed", options.seed, "seed of the samples' values")->capture_default_str();
    command.add_flag("--marker", options.marker, "every double is the marker pattern");
    command.add_option("--partition", options.partition, "DDS partition (default: the default partition)");
    command.add_option("--topic", options.topic, "RobotState topic")->capture_default_str();
  };
  CLI::App* publish = app.add_subcommand("publish", "write the samples, then wait for stdin to close");
  CLI::App* subscribe =
      app.add_subcommand("subscribe", "check the samples as they arrive until stdin closes");
  add_options(*publish);
  add_options(*subscribe);
  publish->add_flag("--wait-for-reader", options.wait_for_reader,
                    "write only once a reader matched (up to 60 s), for volatile readers");
  CLI11_PARSE(app, argc, argv);

  log_fast_dds_to_stderr();
  try {
    run(options, publish->parsed());
    return 0;
  } catch (const std::exception& error) {
    std::cerr << "rsg_secure_probe: " << error.what() << "\n";
    return 1;
  }
}
