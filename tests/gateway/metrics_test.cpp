// The Prometheus text exposition of the gateway's counters (src/gateway/metrics.hpp). That
// Prometheus itself accepts it is shown by integration.metrics_prometheus (promtool and a real
// server); here: what each line says.
#include "gateway/metrics.hpp"

#include <gtest/gtest.h>

#include <map>
#include <set>
#include <sstream>

namespace rsg::gateway {
namespace {

MetricsSnapshot example() {
  MetricsSnapshot snapshot;
  snapshot.has_ingress = true;
  snapshot.gateway = "robot1";
  snapshot.partition = "cell \"A\"\\2";
  snapshot.version = "0.1.0";
  snapshot.fastdds_version = "2.9.1";
  snapshot.link_last_change_s = 1764165600.5;
  auto& stats = snapshot.stats;
  stats.ingress.received = 1200;
  stats.ingress.published = 1000;
  stats.ingress.invalid[status::invalid_index(wire::ErrorCategory::kBadCrc)] = 150;
  stats.ingress.invalid[status::invalid_index(wire::ErrorCategory::kTruncated)] = 50;
  stats.ingress.rejected_source = 7;
  stats.sequence.lost = 3;
  stats.egress.frames_sent = 42;
  stats.state_readers = 2;
  stats.link_up = true;
  stats.rate_hz = 999.5;
  stats.ingress_delay_us = 250;
  stats.ingress_delay_max_us = 1500;
  snapshot.dumps = DumpCounts{4, 1, 2, 7, 3, 9, 6};
  snapshot.reloads = ReloadCounts{5, 1, 8};
  for (const auto us : {30, 250, 250, 4000}) snapshot.ingress_delay.record(std::chrono::microseconds(us));
  snapshot.frame_age.record(std::chrono::seconds(2));  // above every bound: +Inf only
  return snapshot;
}

// Every sample line: "name{labels}" -> value.
std::map<std::string, std::string> samples(const std::string& text) {
  std::map<std::string, std::string> out;
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) {
    if (line.empty() || line[0] == '#') continue;
    const auto space = line.rfind(' ');
    out[line.substr(0, space)] = line.substr(space + 1);
  }
  return out;
}

constexpr std::string_view kLabels = R"(gateway="robot1",partition="cell \"A\"\\2")";

std::string series(std::string_view name, std::string_view extra = {}) {
  return std::string(name) + "{" + std::string(kLabels) + (extra.empty() ? "" : ",") + std::string(extra) +
         "}";
}

TEST(Metrics, EachCounterOfTheSnapshotIsOneSampleWithTheGatewaysLabels) {
  const auto text = format_metrics(example(), std::nullopt);
  const auto values = samples(text);
  EXPECT_EQ(values.at(series("rsg_frames_received_total")), "1200");
  EXPECT_EQ(values.at(series("rsg_frames_published_total")), "1000");
  EXPECT_EQ(values.at(series("rsg_frames_rejected_source_total")), "7");
  EXPECT_EQ(values.at(series("rsg_frames_lost_total")), "3");
  EXPECT_EQ(values.at(series("rsg_egress_frames_sent_total")), "42");
  EXPECT_EQ(values.at(series("rsg_state_readers")), "2");
  EXPECT_EQ(values.at(series("rsg_link_up")), "1");
  EXPECT_EQ(values.at(series("rsg_frame_rate_hertz")), "999.5");
  EXPECT_EQ(values.at(series("rsg_link_last_change_timestamp_seconds")), "1764165600.5");
  EXPECT_EQ(values.at(series("rsg_ingress_delay_max_seconds")), "0.0015");
  EXPECT_EQ(values.at(series("rsg_build_info", R"(version="0.1.0",fastdds_version="2.9.1")")), "1");
}

// One series per result, zeros included, and the family only with a flight recorder.
TEST(Metrics, FlightRecorderDumpsHaveOneSeriesPerResult) {
  const auto values = samples(format_metrics(example(), std::nullopt));
  EXPECT_EQ(values.at(series("rsg_flight_recorder_dumps_total", R"(result="written")")), "4");
  EXPECT_EQ(values.at(series("rsg_flight_recorder_dumps_total", R"(result="failed")")), "1");
  EXPECT_EQ(values.at(series("rsg_flight_recorder_dumps_total", R"(result="refused")")), "2");
  EXPECT_EQ(values.at(series("rsg_flight_recorder_dumps_total", R"(result="throttled")")), "7");
  EXPECT_EQ(values.at(series("rsg_flight_recorder_files_deleted_total")), "3");
  EXPECT_EQ(values.at(series("rsg_flight_recorder_datagrams_not_kept_total")), "9");
  EXPECT_EQ(values.at(series("rsg_config_reloads_total", R"(result="applied")")), "5");
  EXPECT_EQ(values.at(series("rsg_config_reloads_total", R"(result="failed")")), "1");
  EXPECT_EQ(values.at(series("rsg_config_reloads_total", R"(result="refused")")), "8");
  EXPECT_EQ(values.at(series("rsg_flight_recorder_dumps_total", R"(result="no_room")")), "6");
  MetricsSnapshot without = example();
  without.dumps.reset();
  EXPECT_EQ(format_metrics(without, std::nullopt).find("rsg_flight_recorder"), std::string::npos);
}

TEST(Metrics, InvalidFramesHaveOneSeriesPerSpecCategoryZerosIncluded) {
  const auto values = samples(format_metrics(example(), std::nullopt));
  for (std::size_t i = 0; i < wire::kErrorCategoryCount; ++i) {
    const auto category = status::category_at(i);
    const std::string expected = category == wire::ErrorCategory::kBadCrc      ? "150"
                                 : category == wire::ErrorCategory::kTruncated ? "50"
                                                                               : "0";
    EXPECT_EQ(values.at(series("rsg_frames_invalid_total",
                               "category=\"" + std::string(wire::to_string(category)) + "\"")),
              expected)
        << wire::to_string(category);
  }
}

TEST(Metrics, EveryFamilyHasHelpAndTypeBeforeItsSamplesAndCountersEndInTotal) {
  ProcessFigures process{12.5, 4096.0 * 1000, 1764160000.0, 17};
  const auto text = format_metrics(example(), process);
  std::istringstream lines(text);
  std::map<std::string, std::string> types;
  std::set<std::string> helped, sampled;
  for (std::string line; std::getline(lines, line);) {
    std::istringstream words(line);
    std::string first, name, type;
    words >> first;
    if (first == "#") {
      std::string keyword;
      words >> keyword >> name;
      if (keyword == "HELP") {
        EXPECT_FALSE(sampled.contains(name)) << name << ": HELP after its samples";
        helped.insert(name);
      } else if (keyword == "TYPE") {
        words >> type;
        EXPECT_TRUE(types.emplace(name, type).second) << name << ": two TYPE lines";
      }
      continue;
    }
    name = first.substr(0, first.find('{'));
    for (const std::string_view suffix : {"_bucket", "_sum", "_count"})
      if (name.ends_with(suffix) && types[name.substr(0, name.size() - suffix.size())] == "histogram")
        name.resize(name.size() - suffix.size());
    std::erase_if(types, [](const auto& entry) { return entry.second.empty(); });
    ASSERT_TRUE(types.contains(name)) << name << ": a sample before its TYPE";
    sampled.insert(name);
  }
  const auto names = metric_family_names();
  EXPECT_EQ(std::set<std::string>(names.begin(), names.end()), sampled);
  for (const auto& [name, type] : types) {
    EXPECT_TRUE(helped.contains(name)) << name;
    EXPECT_EQ(type == "counter", name.ends_with("_total")) << name << " is a " << type;
    EXPECT_TRUE(type == "counter" || type == "gauge" || type == "histogram") << name;
  }
  const auto values = samples(text);
  EXPECT_EQ(values.at(series("process_cpu_seconds_total")), "12.5");
  EXPECT_EQ(values.at(series("process_resident_memory_bytes")), "4096000");
}

TEST(Metrics, WithoutAPartitionTheSeriesCarryTheGatewayLabelOnly) {
  MetricsSnapshot snapshot = example();
  snapshot.partition.clear();
  const auto values = samples(format_metrics(snapshot, std::nullopt));
  EXPECT_EQ(values.at("rsg_frames_published_total{gateway=\"robot1\"}"), "1000");
  EXPECT_EQ(values.at("rsg_frames_invalid_total{gateway=\"robot1\",category=\"bad_crc\"}"), "150");
}

// Prometheus' histogram: cumulative _bucket series by `le` up to +Inf, then _sum and _count.
TEST(Metrics, IngressDelayAndFrameAgeAreHistogramsWithCumulativeBuckets) {
  const auto text = format_metrics(example(), std::nullopt);
  EXPECT_NE(text.find("# TYPE rsg_ingress_delay_seconds histogram\n"), std::string::npos);
  EXPECT_NE(text.find("# TYPE rsg_frame_age_seconds histogram\n"), std::string::npos);
  const auto values = samples(text);
  const auto bucket = [&](std::string_view name, std::string_view le) {
    return values.at(series(name, "le=\"" + std::string(le) + "\""));
  };
  EXPECT_EQ(bucket("rsg_ingress_delay_seconds_bucket", "5e-05"), "1");
  EXPECT_EQ(bucket("rsg_ingress_delay_seconds_bucket", "0.0001"), "1");
  EXPECT_EQ(bucket("rsg_ingress_delay_seconds_bucket", "0.00025"), "3");  // le: 250 us counts in 0.00025
  EXPECT_EQ(bucket("rsg_ingress_delay_seconds_bucket", "0.0025"), "3");
  EXPECT_EQ(bucket("rsg_ingress_delay_seconds_bucket", "0.005"), "4");
  EXPECT_EQ(bucket("rsg_ingress_delay_seconds_bucket", "1"), "4");
  EXPECT_EQ(bucket("rsg_ingress_delay_seconds_bucket", "+Inf"), "4");
  EXPECT_EQ(values.at(series("rsg_ingress_delay_seconds_count")), "4");
  EXPECT_EQ(values.at(series("rsg_ingress_delay_seconds_sum")), "0.00453");
  EXPECT_EQ(bucket("rsg_frame_age_seconds_bucket", "1"), "0");
  EXPECT_EQ(bucket("rsg_frame_age_seconds_bucket", "+Inf"), "1");
  EXPECT_EQ(values.at(series("rsg_frame_age_seconds_sum")), "2");
  MetricsSnapshot egress_only = example();
  egress_only.has_ingress = false;
  EXPECT_EQ(format_metrics(egress_only, std::nullopt).find("rsg_ingress_delay_seconds_bucket"),
            std::string::npos);
}

TEST(Metrics, LabelValuesEscapeBackslashQuoteAndLineFeed) {
  EXPECT_EQ(escape_label_value("a\\b\"c\nd"), "a\\\\b\\\"c\\nd");
}

TEST(Metrics, TheProcessFiguresOfThisProcessAreRead) {
  const auto process = read_process_figures();
  ASSERT_TRUE(process.has_value());
  EXPECT_GT(process->resident_bytes, 0);
  EXPECT_GT(process->start_time_s, 1.6e9);  // after 2020
  EXPECT_GE(process->open_fds, 3);          // stdin, stdout, stderr
}

TEST(Metrics, LiveWhileTheSnapshotIsFreshReadyWhileTheLinkIsUpToo) {
  MetricsSnapshot snapshot = example();
  const auto now = Clock::now();
  snapshot.taken = now;
  const auto max_age = std::chrono::seconds(3);
  EXPECT_TRUE(is_ready(snapshot, now + std::chrono::seconds(1), max_age));
  EXPECT_TRUE(is_live(snapshot, now + std::chrono::seconds(1), max_age));
  EXPECT_FALSE(is_ready(snapshot, now + std::chrono::seconds(4), max_age)) << "a stale snapshot";
  EXPECT_FALSE(is_live(snapshot, now + std::chrono::seconds(4), max_age)) << "a stale snapshot";
  snapshot.stats.link_up = false;
  EXPECT_FALSE(is_ready(snapshot, now, max_age)) << "link down";
  EXPECT_TRUE(is_live(snapshot, now, max_age)) << "link down: waiting for the robot is alive";
  snapshot.has_ingress = false;
  EXPECT_TRUE(is_ready(snapshot, now, max_age)) << "egress only: no link to watch";
}

TEST(Metrics, NotReadyWhileAnotherRobotWritesInThePartition) {
  MetricsSnapshot snapshot = example();
  const auto now = Clock::now();
  snapshot.taken = now;
  const auto max_age = std::chrono::seconds(3);
  ASSERT_TRUE(is_ready(snapshot, now, max_age));
  snapshot.stats.other_state_writers = 1;
  EXPECT_FALSE(is_ready(snapshot, now, max_age)) << "its readers get two robots' samples";
  EXPECT_TRUE(is_live(snapshot, now, max_age)) << "restarting it would not help";
  const std::string text = format_metrics(snapshot, std::nullopt);
  EXPECT_NE(text.find("rsg_state_other_writers{gateway=\""), std::string::npos) << text;
}

}  // namespace
}  // namespace rsg::gateway
