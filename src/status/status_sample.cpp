#include "status/status_sample.hpp"

#include <cstring>

namespace rsg::status {
namespace {

// The IDL names each category so that DDS tools show them, and declares them in ErrorCategory
// order; fastddsgen lays the members out as declared, so the counters are copied as one block.
// tests/status/status_sample_test.cpp checks every name against its category.
static_assert(sizeof(InvalidFrameCounts) == sizeof(InvalidCounts));

void copy_invalid(const InvalidCounts& counts, InvalidFrameCounts& target) {
  std::memcpy(static_cast<void*>(&target), counts.data(), sizeof counts);
}

InvalidCounts copy_invalid(const InvalidFrameCounts& source) {
  InvalidCounts counts;
  std::memcpy(counts.data(), static_cast<const void*>(&source), sizeof counts);
  return counts;
}

}  // namespace

void to_status_sample(const GatewayStats& stats, GatewayStatus& sample) {
  sample.source(stats.source);  // fixed_string cuts what exceeds the bound
  sample.link_up(stats.link_up);
  sample.rate_hz(stats.rate_hz);
  sample.frames_received(stats.ingress.received);
  sample.frames_published(stats.ingress.published);
  sample.publish_failed(stats.ingress.publish_failed);
  copy_invalid(stats.ingress.invalid, sample.invalid());
  sample.rejected_source(stats.ingress.rejected_source);
  sample.lost(stats.sequence.lost);
  sample.duplicated(stats.sequence.duplicated);
  sample.reordered(stats.sequence.reordered);
  sample.robot_restarts(stats.sequence.restarts);
  sample.out_of_sequence(stats.sequence.out_of_sequence);
  sample.state_readers(stats.state_readers);
  sample.egress_writers(stats.egress_writers);
  sample.standard_readers(stats.standard_readers);
  sample.egress_samples(stats.egress.samples);
  sample.egress_frames_sent(stats.egress.frames_sent);
  sample.egress_unencodable(stats.egress.unencodable);
  sample.egress_send_failed(stats.egress.send_failed);
  sample.egress_request_like(stats.egress.request_like);
  sample.egress_rate_limited(stats.egress.rate_limited);
  sample.standard_dropped(stats.standard_dropped);
  sample.ingress_delay_us(stats.ingress_delay_us);
  sample.ingress_delay_max_us(stats.ingress_delay_max_us);
}

GatewayStats from_status_sample(const GatewayStatus& sample) {
  GatewayStats stats;
  stats.source = sample.source().c_str();
  stats.link_up = sample.link_up();
  stats.rate_hz = sample.rate_hz();
  stats.ingress.received = sample.frames_received();
  stats.ingress.published = sample.frames_published();
  stats.ingress.publish_failed = sample.publish_failed();
  stats.ingress.invalid = copy_invalid(sample.invalid());
  stats.ingress.rejected_source = sample.rejected_source();
  stats.sequence = {.lost = sample.lost(),
                    .duplicated = sample.duplicated(),
                    .reordered = sample.reordered(),
                    .restarts = sample.robot_restarts(),
                    .out_of_sequence = sample.out_of_sequence()};
  stats.state_readers = sample.state_readers();
  stats.egress_writers = sample.egress_writers();
  stats.standard_readers = sample.standard_readers();
  stats.egress = {.samples = sample.egress_samples(),
                  .frames_sent = sample.egress_frames_sent(),
                  .unencodable = sample.egress_unencodable(),
                  .send_failed = sample.egress_send_failed(),
                  .request_like = sample.egress_request_like(),
                  .rate_limited = sample.egress_rate_limited()};
  stats.standard_dropped = sample.standard_dropped();
  stats.ingress_delay_us = sample.ingress_delay_us();
  stats.ingress_delay_max_us = sample.ingress_delay_max_us();
  return stats;
}

}  // namespace rsg::status
