#include "state_subscriber.hpp"

#include <fastdds/dds/core/LoanableSequence.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fstream>
#include <stdexcept>
#include <thread>

namespace rsg::bench {
namespace {

constexpr auto kPollInterval = std::chrono::milliseconds(10);

template <typename Predicate>
bool poll_until(std::chrono::milliseconds timeout, Predicate done) {
  const auto deadline = Clock::now() + timeout;
  while (!done()) {
    if (Clock::now() >= deadline) return false;
    std::this_thread::sleep_for(kPollInterval);
  }
  return true;
}

}  // namespace

StateSubscriber::StateSubscriber(Participant& participant, const std::string& topic,
                                 const std::string& reader_profile, LatencyLog& log)
    : participant_(participant), log_(log), subscriber_(participant.subscriber()) {
  reader_ = subscriber_->create_datareader_with_profile(participant.robot_state_topic(topic), reader_profile,
                                                        this, fdds::StatusMask::data_available());
  if (!reader_) {
    participant_.get()->delete_subscriber(subscriber_);
    throw std::runtime_error("cannot create a RobotState reader with profile '" + reader_profile + "'");
  }
}

StateSubscriber::~StateSubscriber() {
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

void StateSubscriber::on_data_available(fdds::DataReader* reader) {
  fdds::LoanableSequence<RobotState> samples;
  fdds::SampleInfoSeq infos;
  while (reader->take(samples, infos) == ReturnCode_t::RETCODE_OK) {
    const std::int64_t received_ns = monotonic_ns();
    for (fdds::LoanableCollection::size_type i = 0; i < samples.length(); ++i)
      if (infos[i].valid_data) log_.record(read_stamp(samples[i]), received_ns);
    reader->return_loan(samples, infos);
  }
}

bool maps_data_sharing_segment() {
  std::ifstream maps("/proc/self/maps");
  for (std::string line; std::getline(maps, line);)
    if (line.find("/dev/shm/fast_datasharing") != std::string::npos) return true;
  return false;
}

}  // namespace rsg::bench
