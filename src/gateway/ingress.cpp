#include "gateway/ingress.hpp"

#include <spdlog/spdlog.h>

#include <fastdds/dds/publisher/DataWriter.hpp>

#include "dds/internal/fastdds_compat.hpp"  // is_plain
#include "gateway/entities.hpp"

namespace rsg::gateway {
namespace fdds = eprosima::fastdds::dds;
namespace {

// The robot's `time`, from the sample the codec just decoded the frame into, when the frame carried it.
std::optional<std::uint64_t> frame_time(const wire::FrameView& frame, const RobotState& sample) {
  if (!frame.contains(wire::Field::time)) return std::nullopt;
  return sample.time();
}

// When the kernel queued a datagram, on the gateway's clock: `arrived` is wall-clock time, and
// `wall_now` and `now` were read together. A datagram without a time stamp counts as arriving now.
Clock::time_point arrival_of(std::chrono::system_clock::time_point arrived, Clock::time_point now,
                             std::chrono::system_clock::time_point wall_now) {
  if (arrived.time_since_epoch().count() == 0 || arrived > wall_now) return now;
  return now - std::chrono::duration_cast<Clock::duration>(wall_now - arrived);
}

/// The sample a frame is decoded into: a loan from the writer when it has one to give, else the
/// preallocated sample. A loan that is not written goes back to the writer.
class SampleSlot {
 public:
  SampleSlot(fdds::DataWriter& writer, bool loans, RobotState& fallback)
      : writer_(writer), fallback_(&fallback), sample_(&fallback) {
    // No initialisation of the loan: a successful decode writes every member (header,
    // group_present and each field, absent ones zeroed; robot_state_mapping_test checks it on
    // poisoned memory), so constructing the sample first would only cost CPU on every frame
    // (docs/benchmarks/e2e.md). Without a loan (type not plain, every loanable slot in use): the
    // fallback.
    if (loans &&
        writer_.loan_sample(loan_, fdds::DataWriter::LoanInitializationKind::NO_LOAN_INITIALIZATION) ==
            rsg::dds::kOk)
      sample_ = static_cast<RobotState*>(loan_);
  }
  ~SampleSlot() {
    if (loan_ != nullptr) writer_.discard_loan(loan_);
  }
  SampleSlot(const SampleSlot&) = delete;
  SampleSlot& operator=(const SampleSlot&) = delete;

  RobotState& sample() { return *sample_; }

  /// Moves the sample out of its loan into the fallback and gives the loan back: the writer lends
  /// one sample beyond its history, and another write (the held frame's) needs it first.
  void release_loan() {
    if (loan_ == nullptr) return;
    *fallback_ = *sample_;
    writer_.discard_loan(loan_);
    loan_ = nullptr;
    sample_ = fallback_;
  }

  /// Writes the sample; a written loan belongs to the writer from then on.
  bool write() {
    const bool written = dds::succeeded(writer_.write(sample_));
    if (written) loan_ = nullptr;
    return written;
  }

 private:
  fdds::DataWriter& writer_;
  void* loan_ = nullptr;
  RobotState* fallback_;
  RobotState* sample_;
};

}  // namespace

Ingress::Ingress(dds::Participant& participant, Options options)
    : options_(std::move(options)),
      socket_(transport::UdpSocket::bind(options_.listen)),
      participant_(participant),
      batch_(kBatchDatagrams, wire::kMaxFrameBytes),
      sequence_(options_.restart_threshold_ms, LinkMonitor(options_.nominal_period).silence_limit()),
      link_(options_.nominal_period) {
  // The link monitor and the delay counters judge by when frames arrived, not by when a busy
  // ingress got round to them.
  socket_.timestamp_arrivals();
  if (options_.receive_buffer > 0) {
    const int granted = socket_.set_receive_buffer(options_.receive_buffer);
    if (granted < options_.receive_buffer)
      spdlog::warn("UDP receive buffer is {} bytes, not the {} asked for (raise net.core.rmem_max)", granted,
                   options_.receive_buffer);
  }
  if (options_.requested_selection) requester_.emplace(*options_.requested_selection);
  if (options_.flight_recorder) {
    recorder_.emplace(*options_.flight_recorder, socket_.local_endpoint(), batch_);
    spdlog::info("flight recorder: the last {} s of datagrams ({} at most) for {}",
                 options_.flight_recorder->window.count(), recorder_->capacity(),
                 options_.flight_recorder->dir.string());
  }

  // Should anything below throw, the owners built so far delete their entities.
  publisher_ = dds::own(participant_, participant_.publisher(options_.partitions));
  fdds::Topic* topic = participant_.robot_state_topic(options_.topic, options_.type_name);
  writer_ =
      dds::own(*publisher_,
               create_writer_with_profile(*publisher_, topic, options_.writer_profile, options_.data_sharing),
               "the RobotState writer with profile '" + options_.writer_profile + "'");
  for (const auto& rate : options_.rate_topics) {
    fdds::Topic* rate_topic = participant_.robot_state_topic(rate.topic, options_.type_name);
    rate_writers_.push_back(
        {dds::own(*publisher_,
                  create_writer_with_profile(*publisher_, rate_topic, options_.writer_profile,
                                             options_.data_sharing),
                  "the writer of --rate-topic '" + rate.topic + "'"),
         Decimator(rate.rate)});
  }
  if (options_.standard_topics && options_.standard_topics->any())
    standard_topics_.emplace(participant_, *publisher_, *options_.standard_topics);
  // Loans need a plain type; RobotState is one, but a profile could still make writes non-loanable.
  writer_loans_ = dds::internal::is_plain(*writer_->get_type());
}

// The members' owners delete the standard topics' writers (after their thread), the rate writers,
// the writer and the publisher, in that order.
Ingress::~Ingress() = default;

void Ingress::start(Clock::time_point now) {
  if (requester_ && options_.robot && requester_->start_up_due(now)) request_selection(*options_.robot);
}

void Ingress::receive(std::chrono::milliseconds timeout) {
  if (!socket_.wait_readable(timeout)) return;
  for (std::size_t round = 0; round < kMaxBatchesPerWake; ++round) {
    if (recorder_) recorder_->lend(batch_);
    const std::size_t received = socket_.receive_batch(batch_);
    // Every datagram of a batch was queued by now: one clock reading serves them all.
    const auto now = Clock::now();
    const auto wall_now = std::chrono::system_clock::now();
    for (std::size_t i = 0; i < received; ++i) {
      const transport::DatagramBatch::Datagram datagram = batch_[i];
      handle(datagram, now, arrival_of(datagram.arrived, now, wall_now));
    }
    // After handling: keeping only allowed senders' datagrams moves bytes within the batch's slots.
    if (recorder_ && received) recorder_->commit(batch_, received, wall_now, options_.sources);
    if (received < batch_.capacity()) return;  // the queue was empty; the next poll waits for more
  }
}

void Ingress::handle(const transport::DatagramBatch::Datagram& datagram, Clock::time_point now,
                     Clock::time_point arrival) {
  if (!options_.sources.allows(datagram.from.address())) {
    ++counters_.rejected_source;
    last_foreign_sender_ = datagram.from;
    return;
  }
  ++counters_.received;

  // Longer than any frame, so never valid; decoding the part that fit could pass it off as a
  // valid frame of that length. length_mismatch, as docs/protocol.md's step 1 ranks it for every
  // decoder, whatever the cut-off bytes held.
  if (datagram.truncated) {
    reject({wire::ErrorCategory::kLengthMismatch, "%zu bytes, longer than any frame (%zu)", datagram.size,
            wire::kMaxFrameBytes},
           datagram.from);
    return;
  }
  // Decoded straight into the sample that gets written: the payload's one copy happens in the
  // same pass as the CRC check. A rejected frame's sample goes back unwritten.
  // With an in-process consumer the frame is decoded into the preallocated sample, not a loan:
  // loaning takes the writer's lock, which Fast DDS's event thread may hold, and the consumer
  // must not wait for it. write() then copies the sample into the writer's history.
  SampleSlot slot(*writer_, writer_loans_ && !options_.on_sample, fallback_sample_);
  const wire::DecodeResult decoded = codec_.decode(datagram.bytes, slot.sample());
  if (!decoded) {
    reject(decoded.error(), datagram.from);
    return;
  }
  const wire::FrameView& frame = decoded.frame();

  const std::optional<std::uint64_t> robot_time_ms = frame_time(frame, slot.sample());
  const std::uint64_t restarts = sequence_.counts().restarts;
  // A frame that does not continue the stream (late, replayed, forged: sequence_tracker.hpp) is
  // counted there and goes no further: no consumer, rate topic or link state sees it. The one that
  // may start a restarted sequence is kept, to go out first should the next frame confirm it.
  switch (sequence_.observe(frame.packet_number(), robot_time_ms, arrival)) {
    case status::SequenceTracker::Verdict::kOutOfSequence:
      return;
    case status::SequenceTracker::Verdict::kHeld:
      held_sample_ = slot.sample();  // a plain copy into storage allocated at start-up
      held_selection_ = frame.selection();
      held_time_ms_ = robot_time_ms;
      return;
    case status::SequenceTracker::Verdict::kInSequence:
      break;
  }
  if (sequence_.counts().restarts != restarts)  // the robot's clock began again: so do the ages
    age_floor_ns_ = age_floor_last_ns_ = kNoFloor;
  link_came_up_ |= link_.on_frame(arrival);
  source_ = datagram.from;
  if (requester_ && requester_->due(frame.selection(), now))
    request_selection(options_.robot ? *options_.robot : datagram.from);

  if (sequence_.releases_held()) {
    deliver(held_sample_, held_selection_, held_time_ms_, now);
    slot.release_loan();
    count_write(dds::succeeded(writer_->write(&held_sample_)));  // a copy into the writer's history
  }
  deliver(slot.sample(), frame.selection(), robot_time_ms, now);
  count_write(slot.write());
  const auto published = Clock::now();
  const auto delay = published - arrival;
  delay_period_max_ = std::max(delay_period_max_, delay);
  delay_max_ = std::max(delay_max_, delay);
  delay_histogram_.record(delay);
  if (robot_time_ms) record_age(*robot_time_ms, arrival, published);
}

void Ingress::record_age(std::uint64_t robot_time_ms, Clock::time_point arrival,
                         Clock::time_point published) {
  const auto ns = [](Clock::time_point t) {
    return std::chrono::duration_cast<std::chrono::nanoseconds>(t.time_since_epoch()).count();
  };
  const std::int64_t robot_ns = static_cast<std::int64_t>(robot_time_ms) * 1'000'000;
  age_floor_ns_ = std::min(age_floor_ns_, ns(arrival) - robot_ns);
  const std::int64_t floor = std::min(age_floor_ns_, age_floor_last_ns_);
  age_histogram_.record(std::chrono::nanoseconds(ns(published) - robot_ns - floor));
}

void Ingress::deliver(const RobotState& sample, const wire::Selection& selection,
                      std::optional<std::uint64_t> robot_time_ms, Clock::time_point now) {
  if (options_.on_sample) options_.on_sample(sample);
  // Before the full-rate write, which hands a loaned sample over to the middleware. The slower
  // outputs are paced by the robot's time when the frame carries it, else by arrival.
  if (rate_writers_.empty() && !standard_topics_) return;
  const std::chrono::nanoseconds t = robot_time_ms
                                         ? std::chrono::nanoseconds(std::chrono::milliseconds(*robot_time_ms))
                                         : std::chrono::nanoseconds(now.time_since_epoch());
  if (!rate_writers_.empty()) write_rate_topics(sample, t);
  if (standard_topics_) standard_topics_->offer(sample, selection, t);
}

void Ingress::count_write(bool written) {
  if (written)
    ++counters_.published;
  else
    ++counters_.publish_failed;
}

void Ingress::write_rate_topics(const RobotState& sample, std::chrono::nanoseconds t) {
  for (RateWriter& rate : rate_writers_)
    if (rate.decimator.due(t))
      rate.writer->write(const_cast<RobotState*>(&sample));  // a copy into the writer's own history
}

void Ingress::reject(const wire::FrameError& error, const transport::Endpoint& sender) {
  ++counters_.invalid[status::invalid_index(error.category())];
  sequence_.on_invalid();  // counted as invalid, not also as lost
  last_rejection_ = error;
  last_rejected_sender_ = sender;
}

void Ingress::request_selection(const transport::Endpoint& robot) {
  std::array<std::uint8_t, wire::kSelectionRequestBytes> request{};
  const wire::EncodeResult encoded =
      encode_selection_request(request_packet_number_, requester_->wanted(), request);
  request_packet_number_ =
      static_cast<std::uint8_t>((request_packet_number_ + 1) % wire::kPacketNumberModulo);
  // From the listening socket, so that the robot's answer (its stream) comes back to it. Rare (at
  // most once a second), so it may log.
  if (encoded && socket_.send_to(std::span(request).first(encoded.size), robot))
    requester_->log_sent(robot.to_string(), source_.size() ? source_.to_string() : std::string());
  else if (const auto n = request_failed_log_.take(Clock::now()))
    spdlog::warn("could not send the selection request to {} ({} times since the last such line)",
                 robot.to_string(), n);
}

void Ingress::set_sources(SourceFilter sources) { options_.sources = std::move(sources); }

std::optional<FlightRecorder::Snapshot> Ingress::flight_recorder_snapshot(std::string_view reason) {
  if (!recorder_) return std::nullopt;
  return recorder_->snapshot(reason);
}

bool Ingress::link_changed(Clock::time_point now) {
  const bool came_up = std::exchange(link_came_up_, false);
  // Silence is judged only with the socket drained: a datagram still queued arrived after the
  // last one handled, so the robot was not silent, however long the gateway took to get here.
  const bool went_down = link_.up() && now >= link_.deadline() && !socket_.has_queued() && link_.poll(now);
  return came_up || went_down;
}

void Ingress::end_status_period() {
  delay_period_max_ = {};
  age_floor_last_ns_ = std::exchange(age_floor_ns_, kNoFloor);
}

void Ingress::fill(status::GatewayStats& stats) const {
  stats.ingress = counters_;
  stats.sequence = sequence_.counts();
  stats.link_up = link_.up();
  fdds::PublicationMatchedStatus matched;
  writer_->get_publication_matched_status(matched);
  stats.state_readers = static_cast<std::uint32_t>(matched.current_count);
  stats.source = source_.size() ? source_.to_string() : std::string();
  stats.standard_dropped = standard_topics_ ? standard_topics_->dropped() : 0;
  stats.standard_readers = standard_topics_ ? standard_topics_->matched_readers() : 0;
  const auto micros = [](Clock::duration d) {
    return static_cast<std::uint64_t>(std::chrono::duration_cast<std::chrono::microseconds>(d).count());
  };
  stats.ingress_delay_us = micros(delay_period_max_);
  stats.ingress_delay_max_us = micros(delay_max_);
}

void Ingress::log_rejections(Clock::time_point now) {
  // Each kind: the counts since its last line, once its RepeatedLog says a line is due.
  if (rejected_source_log_.take(now, counters_.rejected_source - counted_rejected_source_) > 0) {
    spdlog::warn("ignored {} datagrams from outside --allow-from since the last line, the last from {}",
                 counters_.rejected_source - logged_rejected_source_, last_foreign_sender_.to_string());
    logged_rejected_source_ = counters_.rejected_source;
  }
  counted_rejected_source_ = counters_.rejected_source;

  std::uint64_t invalid = 0;
  for (const std::uint64_t count : counters_.invalid) invalid += count;
  if (invalid_log_.take(now, invalid - counted_invalid_) > 0) {
    status::InvalidCounts fresh{};
    for (std::size_t i = 0; i < fresh.size(); ++i) fresh[i] = counters_.invalid[i] - logged_invalid_[i];
    spdlog::warn("rejected invalid frames since the last line: {}; the last from {}: {}: {}",
                 status::format_invalid(fresh), last_rejected_sender_.to_string(),
                 wire::to_string(last_rejection_.category()), last_rejection_.message());
    logged_invalid_ = counters_.invalid;
  }
  counted_invalid_ = invalid;

  if (standard_topics_) {
    const std::uint64_t dropped = standard_topics_->dropped();
    if (standard_dropped_log_.take(now, dropped - counted_standard_dropped_) > 0) {
      spdlog::warn(
          "ROS 2 standard topics: {} snapshots dropped since the last line, their publishing thread "
          "is behind",
          dropped - logged_standard_dropped_);
      logged_standard_dropped_ = dropped;
    }
    counted_standard_dropped_ = dropped;
  }
}

}  // namespace rsg::gateway
