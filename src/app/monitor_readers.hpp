// The DDS side of the tools that watch a gateway (rsg_record, rsg_view): a RobotState reader, on
// the whole topic or through a view, an optional GatewayStatus reader, and one wait set that wakes
// on data from either or on a stop request (e.g. from StopOnSignal).
#pragma once

#include <GatewayStatusPubSubTypes.h>

#include <chrono>
#include <fastdds/dds/core/condition/GuardCondition.hpp>
#include <fastdds/dds/core/condition/WaitSet.hpp>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "rsg/dds/fastdds.hpp"
#include "rsg/dds/participant.hpp"
#include "rsg/dds/profiles.hpp"
#include "rsg/dds/views.hpp"
#include "rsg/error.hpp"

namespace rsg::app {

/// When wait() returns: as soon as a sample arrives (a live view), or only when its timeout passes
/// (a recorder that takes samples in batches and so wakes once per batch, not once per sample).
enum class WakeUp { kOnData, kPeriodically };

struct MonitorTopics {
  std::string topic;         ///< RobotState
  std::string status_topic;  ///< GatewayStatus; empty: none
  std::vector<std::string> partitions;
  std::string view_profile;  ///< empty: the whole topic
  std::string qos_profile;   ///< of the RobotState reader
};

/// The readers belong to `participant`'s subscriber, which must outlive this object.
class MonitorReaders {
 public:
  /// @throws rsg::dds::ViewError for an unusable view profile, rsg::EnvironmentError when Fast DDS
  /// refuses a reader.
  MonitorReaders(dds::Participant& participant, const MonitorTopics& topics, WakeUp wake = WakeUp::kOnData) {
    namespace fdds = eprosima::fastdds::dds;
    fdds::Topic& topic = *participant.robot_state_topic(topics.topic);
    fdds::Subscriber& subscriber = *participant.subscriber(topics.partitions);
    const fdds::DataReaderQos qos = dds::load_reader_qos(subscriber, topics.qos_profile);
    if (!topics.view_profile.empty()) {
      view_reader_.emplace(subscriber, topic, dds::load_view(subscriber, topics.view_profile), qos);
      state_ = view_reader_->get();
    } else {
      state_ = subscriber.create_datareader(&topic, qos);
      if (state_ == nullptr) throw EnvironmentError("cannot create a reader on '" + topics.topic + "'");
    }
    if (!topics.status_topic.empty()) {
      fdds::Topic* status_topic =
          participant.topic(topics.status_topic, fdds::TypeSupport(new GatewayStatusPubSubType()));
      status_ = subscriber.create_datareader_with_profile(status_topic, "rsg_status_reader");
      if (status_ == nullptr)
        throw EnvironmentError("cannot create a reader on '" + topics.status_topic + "'");
    }
    for (fdds::DataReader* reader : {state_, status_}) {
      if (reader == nullptr || wake == WakeUp::kPeriodically) continue;
      reader->get_statuscondition().set_enabled_statuses(fdds::StatusMask::data_available());
      waitset_.attach_condition(reader->get_statuscondition());
    }
    waitset_.attach_condition(stop_);
  }
  MonitorReaders(const MonitorReaders&) = delete;
  MonitorReaders& operator=(const MonitorReaders&) = delete;

  eprosima::fastdds::dds::DataReader& state() { return *state_; }
  /// Null without a status topic.
  eprosima::fastdds::dds::DataReader* status() { return status_; }

  /// Thread-safe: makes wait() return now and stop_requested() true from now on.
  void request_stop() { stop_.set_trigger_value(true); }
  bool stop_requested() const { return stop_.get_trigger_value(); }

  /// Until data arrives on either reader, a stop is requested, or `timeout` passes.
  void wait(std::chrono::nanoseconds timeout) {
    eprosima::fastdds::dds::ConditionSeq triggered;
    waitset_.wait(triggered, rsg::dds::Duration(static_cast<std::int32_t>(timeout.count() / 1'000'000'000),
                                                static_cast<std::uint32_t>(timeout.count() % 1'000'000'000)));
  }

 private:
  std::optional<dds::ViewReader> view_reader_;
  eprosima::fastdds::dds::DataReader* state_ = nullptr;
  eprosima::fastdds::dds::DataReader* status_ = nullptr;
  eprosima::fastdds::dds::GuardCondition stop_;
  eprosima::fastdds::dds::WaitSet waitset_;  // last: detached before the conditions go
};

}  // namespace rsg::app
