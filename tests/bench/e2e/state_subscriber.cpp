#include "tests/bench/e2e/state_subscriber.hpp"

#include <fastdds/dds/core/LoanableSequence.hpp>
#include <fastdds/dds/core/condition/WaitSet.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fstream>
#include <stdexcept>
#include <thread>

#include "rsg/dds/fastdds.hpp"

namespace rsg::bench {
namespace fdds = eprosima::fastdds::dds;
namespace {

constexpr auto kPollStep = std::chrono::milliseconds(10);

template <typename Predicate>
bool poll_until(std::chrono::milliseconds timeout, Predicate done) {
  const auto deadline = Clock::now() + timeout;
  while (!done()) {
    if (Clock::now() >= deadline) return false;
    std::this_thread::sleep_for(kPollStep);
  }
  return true;
}

}  // namespace

StateSubscriber::StateSubscriber(dds::Participant& participant, const std::string& topic,
                                 const std::string& reader_profile, LatencyLog& log, bool waitset,
                                 LatencyLog* notified)
    : participant_(participant), log_(log), notified_(notified), subscriber_(participant.subscriber()) {
  reader_ = subscriber_->create_datareader_with_profile(
      participant.robot_state_topic(topic), reader_profile, waitset ? nullptr : this,
      waitset ? fdds::StatusMask::none() : fdds::StatusMask::data_available());
  if (!reader_) {
    participant_.get()->delete_subscriber(subscriber_);
    throw std::runtime_error("cannot create a RobotState reader with profile '" + reader_profile + "'");
  }
  if (waitset)
    waiting_ = std::thread([this] {
      fdds::StatusCondition& data = reader_->get_statuscondition();
      data.set_enabled_statuses(fdds::StatusMask::data_available());
      fdds::WaitSet waitset;
      waitset.attach_condition(data);
      waitset.attach_condition(stop_);
      fdds::ConditionSeq triggered;
      while (!stop_.get_trigger_value()) {
        waitset.wait(triggered, rsg::dds::kInfinite);
        take_all(reader_, monotonic_ns());
      }
    });
}

StateSubscriber::~StateSubscriber() {
  if (waiting_.joinable()) {
    stop_.set_trigger_value(true);
    waiting_.join();
  }
  // Deleting the reader first guarantees no callback runs once the members are gone.
  subscriber_->delete_datareader(reader_);
  participant_.get()->delete_subscriber(subscriber_);
}

bool StateSubscriber::wait_for_writer(std::chrono::milliseconds timeout) const {
  return poll_until(timeout, [&] {
    fdds::SubscriptionMatchedStatus matched;
    reader_->get_subscription_matched_status(matched);
    return matched.current_count > 0;
  });
}

bool StateSubscriber::wait_for_all(std::chrono::milliseconds timeout) const {
  return poll_until(timeout, [&] { return log_.arrived() == log_.expected(); });
}

void StateSubscriber::on_data_available(fdds::DataReader* reader) { take_all(reader, monotonic_ns()); }

void StateSubscriber::take_all(fdds::DataReader* reader, std::int64_t notified_ns) {
  fdds::LoanableSequence<RobotState> samples;
  fdds::SampleInfoSeq infos;
  while (reader->take(samples, infos) == rsg::dds::kOk) {
    const std::int64_t received_ns = monotonic_ns();
    for (fdds::LoanableCollection::size_type i = 0; i < samples.length(); ++i)
      if (infos[i].valid_data) {
        const Stamp stamp = read_stamp(samples[i]);
        log_.record(stamp, received_ns);
        if (notified_ != nullptr) notified_->record(stamp, notified_ns);
      }
    reader->return_loan(samples, infos);
    notified_ns = monotonic_ns();  // the next take() can only find samples that are there by now
  }
}

bool maps_data_sharing_segment() {
  std::ifstream maps("/proc/self/maps");
  for (std::string line; std::getline(maps, line);)
    if (line.find("/dev/shm/fast_datasharing") != std::string::npos) return true;
  return false;
}

}  // namespace rsg::bench
