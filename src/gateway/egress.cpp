#include "gateway/egress.hpp"

#include <pthread.h>
#include <spdlog/spdlog.h>

#include <fastdds/dds/core/LoanableSequence.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <stdexcept>

#include "gateway/entities.hpp"
#include "rsg/dds/robot_state.hpp"
#include "rsg/error.hpp"

namespace rsg::gateway {
namespace fdds = eprosima::fastdds::dds;
namespace {

// How long the thread sleeps without samples before it looks at its log again.
const rsg::dds::Duration kIdleWake{1, 0};

}  // namespace

Egress::Egress(dds::Participant& participant, const Options& options)
    : participant_(participant),
      budget_(options.max_rate_hz, options.max_rate_hz * kBurstSeconds),
      max_rate_hz_(options.max_rate_hz) {
  for (const transport::Endpoint& endpoint : options.destinations)
    destinations_.push_back({endpoint, transport::UdpSocket::for_sending_to(endpoint)});

  subscriber_ = dds::own(participant_, participant_.subscriber(options.partitions));
  fdds::Topic* topic = participant_.robot_state_topic(options.topic, options.type_name);
  reader_ =
      dds::own(*subscriber_,
               create_reader_with_profile(*subscriber_, topic, options.reader_profile, options.data_sharing),
               "the RobotState reader with profile '" + options.reader_profile + "'");
  reader_->get_statuscondition().set_enabled_statuses(fdds::StatusMask::data_available());
  waitset_.attach_condition(reader_->get_statuscondition());
  waitset_.attach_condition(stop_);
  thread_ = std::jthread([this] { run(); });
}

Egress::~Egress() {
  stop_.set_trigger_value(true);
  thread_.join();
  waitset_.detach_condition(stop_);
  waitset_.detach_condition(reader_->get_statuscondition());
}  // the owners delete the reader, then the subscriber

status::EgressCounters Egress::counters() const {
  return {samples_.load(std::memory_order_relaxed),      frames_sent_.load(std::memory_order_relaxed),
          unencodable_.load(std::memory_order_relaxed),  send_failed_.load(std::memory_order_relaxed),
          request_like_.load(std::memory_order_relaxed), rate_limited_.load(std::memory_order_relaxed)};
}

std::uint32_t Egress::matched_writers() const {
  fdds::SubscriptionMatchedStatus matched;
  reader_->get_subscription_matched_status(matched);
  return static_cast<std::uint32_t>(matched.current_count);
}

void Egress::run() {
  ::pthread_setname_np(::pthread_self(), "rsg-egress");  // top -H, perf, tests find it by name
  fdds::ConditionSeq triggered;
  while (!stop_.get_trigger_value()) {
    waitset_.wait(triggered, kIdleWake);
    forward_available();
    log_unencodable();
    log_refused();
  }
}

void Egress::forward_available() {
  FASTDDS_SEQUENCE(RobotStateSeq, RobotState);
  RobotStateSeq samples;
  fdds::SampleInfoSeq infos;
  while (reader_->take(samples, infos) == rsg::dds::kOk) {
    for (fdds::LoanableCollection::size_type i = 0; i < samples.length(); ++i)
      if (infos[i].valid_data) forward(samples[i]);
    reader_->return_loan(samples, infos);
  }
}

void Egress::forward(const RobotState& sample) {
  samples_.fetch_add(1, std::memory_order_relaxed);
  const wire::EncodeResult encoded = codec_.encode(sample, frame_);
  if (!encoded) {
    unencodable_.fetch_add(1, std::memory_order_relaxed);
    last_encode_error_ = encoded.error;
    return;
  }
  // Header and CRC alone: the robot would take it for a selection request (of whatever the
  // sample selects), not a state.
  if (encoded.size == wire::kSelectionRequestBytes) {
    request_like_.fetch_add(1, std::memory_order_relaxed);
    return;
  }
  if (!budget_.take(Clock::now())) {
    rate_limited_.fetch_add(1, std::memory_order_relaxed);
    return;
  }
  for (Destination& destination : destinations_) {
    if (destination.socket.send_to(std::span(frame_).first(encoded.size), destination.endpoint))
      frames_sent_.fetch_add(1, std::memory_order_relaxed);
    else
      send_failed_.fetch_add(1, std::memory_order_relaxed);
  }
}

void Egress::log_unencodable() {
  const std::uint64_t total = unencodable_.load(std::memory_order_relaxed);
  const std::uint64_t n = unencodable_log_.take(Clock::now(), total - counted_unencodable_);
  counted_unencodable_ = total;
  if (n == 0) return;
  spdlog::warn(
      "{} samples of the egress topic describe no valid frame and were not sent since the last such line; "
      "the "
      "last: {}: {}",
      n, to_string(last_encode_error_.category()), last_encode_error_.message());
}

void Egress::log_refused() {
  // Each kind is logged when it first happens, then at most once a minute with what came since.
  const auto now = Clock::now();
  const std::uint64_t request_like = request_like_.load(std::memory_order_relaxed);
  if (const auto n = request_like_log_.take(now, request_like - counted_request_like_))
    spdlog::warn(
        "{} samples of the egress topic select no field: their frame would read as a selection "
        "request to the robot, so they were not sent (since the last such line)",
        n);
  counted_request_like_ = request_like;
  const std::uint64_t rate_limited = rate_limited_.load(std::memory_order_relaxed);
  if (const auto n = rate_limited_log_.take(now, rate_limited - counted_rate_limited_))
    spdlog::warn(
        "{} samples of the egress topic were not sent: more than --egress-rate {} a second (since the last "
        "such line)",
        n, max_rate_hz_);
  counted_rate_limited_ = rate_limited;
}

}  // namespace rsg::gateway
