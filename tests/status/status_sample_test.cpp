#include "status/status_sample.hpp"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

namespace rsg::status {
namespace {

GatewayStats distinct_stats() {
  GatewayStats stats;
  stats.source = "192.0.2.1:40000";
  stats.link_up = true;
  stats.rate_hz = 999.5;
  stats.ingress.received = 1;
  stats.ingress.published = 2;
  stats.ingress.publish_failed = 3;
  for (std::size_t i = 0; i < stats.ingress.invalid.size(); ++i) stats.ingress.invalid[i] = 100 + i;
  stats.ingress.rejected_source = 4;
  stats.sequence = {.lost = 5, .duplicated = 6, .reordered = 7, .restarts = 8, .out_of_sequence = 19};
  stats.state_readers = 13;
  stats.egress_writers = 14;
  stats.standard_readers = 16;
  stats.egress = {.samples = 9,
                  .frames_sent = 10,
                  .unencodable = 11,
                  .send_failed = 12,
                  .request_like = 20,
                  .rate_limited = 21};
  stats.standard_dropped = 15;
  stats.ingress_delay_us = 17;
  stats.ingress_delay_max_us = 18;
  return stats;
}

// The IDL names the invalid-frame counters; the mapping copies them by position.
TEST(StatusSample, EveryCategoryLandsInTheMemberOfItsName) {
  GatewayStatus sample;
  to_status_sample(distinct_stats(), sample);
  const InvalidFrameCounts& invalid = sample.invalid();
  const auto at = [](wire::ErrorCategory category) { return 100 + invalid_index(category); };
  EXPECT_EQ(invalid.truncated(), at(wire::ErrorCategory::kTruncated));
  EXPECT_EQ(invalid.length_mismatch(), at(wire::ErrorCategory::kLengthMismatch));
  EXPECT_EQ(invalid.bad_crc(), at(wire::ErrorCategory::kBadCrc));
  EXPECT_EQ(invalid.bad_request(), at(wire::ErrorCategory::kBadRequest));
  EXPECT_EQ(invalid.reserved_bits(), at(wire::ErrorCategory::kReservedBits));
  EXPECT_EQ(invalid.selection_mismatch(), at(wire::ErrorCategory::kSelectionMismatch));
  EXPECT_EQ(invalid.bad_value(), at(wire::ErrorCategory::kBadValue));
}

TEST(StatusSample, CountersAndLinkStateAreCopied) {
  GatewayStatus sample;
  to_status_sample(distinct_stats(), sample);
  EXPECT_EQ(std::string(sample.source().c_str()), "192.0.2.1:40000");
  EXPECT_TRUE(sample.link_up());
  EXPECT_EQ(sample.rate_hz(), 999.5);
  EXPECT_EQ(sample.frames_received(), 1U);
  EXPECT_EQ(sample.frames_published(), 2U);
  EXPECT_EQ(sample.publish_failed(), 3U);
  EXPECT_EQ(sample.rejected_source(), 4U);
  EXPECT_EQ(sample.lost(), 5U);
  EXPECT_EQ(sample.duplicated(), 6U);
  EXPECT_EQ(sample.reordered(), 7U);
  EXPECT_EQ(sample.robot_restarts(), 8U);
  EXPECT_EQ(sample.out_of_sequence(), 19U);
  EXPECT_EQ(sample.state_readers(), 13U);
  EXPECT_EQ(sample.egress_writers(), 14U);
  EXPECT_EQ(sample.standard_readers(), 16U);
  EXPECT_EQ(sample.egress_samples(), 9U);
  EXPECT_EQ(sample.egress_frames_sent(), 10U);
  EXPECT_EQ(sample.egress_unencodable(), 11U);
  EXPECT_EQ(sample.egress_send_failed(), 12U);
  EXPECT_EQ(sample.egress_request_like(), 20U);
  EXPECT_EQ(sample.egress_rate_limited(), 21U);
  EXPECT_EQ(sample.standard_dropped(), 15U);
}

TEST(StatusSample, ReadsBackWhatItWrote) {
  GatewayStatus sample;
  to_status_sample(distinct_stats(), sample);
  EXPECT_EQ(to_json(from_status_sample(sample)), to_json(distinct_stats()));
}

TEST(StatusSample, LongSourceIsCutToTheBound) {
  GatewayStats stats;
  stats.source = std::string(200, 'x');
  GatewayStatus sample;
  to_status_sample(stats, sample);
  EXPECT_EQ(std::string(sample.source().c_str()).size(), 64U);
}

TEST(StatsJson, UsesTheStatusNamesAndCategoryNames) {
  const auto json = nlohmann::json::parse(to_json(distinct_stats()));
  EXPECT_EQ(json["frames_received"], 1);
  EXPECT_EQ(json["lost"], 5);
  EXPECT_EQ(json["robot_restarts"], 8);
  EXPECT_EQ(json["invalid"]["truncated"], 100);
  EXPECT_EQ(json["invalid"]["bad_value"], 106);
  EXPECT_EQ(json["invalid"].size(), wire::kErrorCategoryCount);
  EXPECT_EQ(json["source"], "192.0.2.1:40000");
  EXPECT_EQ(json["standard_dropped"], 15);
  EXPECT_EQ(json["ingress_delay_us"], 17);
  EXPECT_EQ(json["ingress_delay_max_us"], 18);
}

TEST(StatsSummary, NamesOnlyTheCategoriesThatOccurred) {
  InvalidCounts counts{};
  counts[invalid_index(wire::ErrorCategory::kBadCrc)] = 3;
  counts[invalid_index(wire::ErrorCategory::kTruncated)] = 1;
  EXPECT_EQ(format_invalid(counts), "truncated=1 bad_crc=3");
  EXPECT_NE(summary_line(distinct_stats()).find("link up"), std::string::npos);
  EXPECT_NE(summary_line(distinct_stats()).find("; standard_dropped 15"), std::string::npos);
  EXPECT_EQ(summary_line(GatewayStats{}).find("standard_dropped"), std::string::npos)
      << "the topics are off, or nothing was dropped: not worth a word";
}

}  // namespace
}  // namespace rsg::status
