// The simulator's stream, checked datagram by datagram against its own report and recording.
#include "tools/sim/simulator.hpp"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <sstream>
#include <vector>

#include "rsg/wire/json.hpp"

namespace rsg::tools::sim {
namespace {

using namespace std::chrono_literals;

// Keeps every datagram, as a receiver that loses nothing would.
class CapturingSink final : public DatagramSink {
 public:
  bool send(std::span<const std::uint8_t> datagram) override {
    datagrams.emplace_back(datagram.begin(), datagram.end());
    return true;
  }
  std::vector<std::vector<std::uint8_t>> datagrams;
};

// What a receiver counts: valid frames, and invalid ones by category.
struct Tally {
  std::uint64_t valid = 0;
  std::array<std::uint64_t, wire::kErrorCategoryCount> invalid{};
  std::vector<wire::StateValues> frames;

  explicit Tally(const CapturingSink& sink) {
    for (const auto& datagram : sink.datagrams) {
      const wire::DecodeResult decoded = wire::decode(datagram);
      if (!decoded) {
        ++invalid[static_cast<std::size_t>(decoded.error().category()) - 1];
        continue;
      }
      ++valid;
      frames.emplace_back().assign(decoded.frame());
    }
  }
};

SimReport run(Simulator& sim, CapturingSink& sink, std::uint64_t frames) {
  for (std::uint64_t i = 0; i < frames; ++i) sim.step(sink);
  sim.finish(sink);
  return sim.report();
}

SimConfig config_with(const char* every) {
  SimConfig config;
  config.schedule = Schedule();
  const wire::Parsed<Schedule::Entry> entry = parse_schedule_entry(every);
  EXPECT_TRUE(entry) << entry.error();
  if (entry) config.schedule.add(*entry);
  return config;
}

TEST(Simulator, CleanStreamNumbersFramesAndStampsTime) {
  SimConfig config = config_with("1:q,time");
  config.rate_hz = 500;
  Simulator sim(config);
  CapturingSink sink;
  run(sim, sink, 40);
  const Tally tally(sink);
  ASSERT_EQ(tally.frames.size(), 40U);
  for (std::size_t i = 0; i < tally.frames.size(); ++i) {
    EXPECT_EQ(tally.frames[i].packet_number, i % 16);
    EXPECT_EQ(tally.frames[i].integer(wire::Field::time), 2 * i);  // 500 Hz: 2 ms apart
  }
}

TEST(Simulator, AboveOneKilohertzTimeRepeatsWholeMilliseconds) {
  SimConfig config = config_with("1:time");
  config.rate_hz = 4000;
  Simulator sim(config);
  CapturingSink sink;
  run(sim, sink, 12);
  const Tally tally(sink);
  for (std::size_t i = 0; i < tally.frames.size(); ++i)
    EXPECT_EQ(tally.frames[i].integer(wire::Field::time), i / 4);
}

TEST(Simulator, FollowsTheSchedulePerFrame) {
  SimConfig config = config_with("1:q");
  const wire::Parsed<Schedule::Entry> entry = parse_schedule_entry("4:g5");
  ASSERT_TRUE(entry) << entry.error();
  config.schedule.add(*entry);
  Simulator sim(config);
  CapturingSink sink;
  run(sim, sink, 9);
  const Tally tally(sink);
  ASSERT_EQ(tally.frames.size(), 9U);
  for (std::size_t i = 0; i < tally.frames.size(); ++i) {
    EXPECT_TRUE(tally.frames[i].selection.contains(wire::Field::q));
    EXPECT_EQ(tally.frames[i].selection.contains(wire::Field::time), i % 4 == 0) << "frame " << i;
  }
}

TEST(Simulator, ReportCountsExactlyWhatWasSent) {
  SimConfig config = config_with("1:q,dq,time,robot_mode");
  config.faults.drop = 0.05;
  config.faults.duplicate = 0.05;
  config.faults.reorder = 0.05;
  config.faults.corrupt = 0.2;
  config.seed = 17;
  Simulator sim(config);
  CapturingSink sink;
  const SimReport report = run(sim, sink, 5000);
  const Tally tally(sink);

  EXPECT_EQ(report.sent, sink.datagrams.size());
  EXPECT_EQ(report.valid, tally.valid);
  EXPECT_EQ(report.invalid, tally.invalid);
  EXPECT_EQ(report.sent, report.valid + report.invalid_total());
  // Every frame was either dropped or sent, duplicates once more.
  EXPECT_EQ(report.sent + report.dropped - report.duplicated, 5000U);
  for (std::uint64_t count : report.invalid) EXPECT_GT(count, 100U);  // all seven categories, fairly
  EXPECT_GT(report.dropped, 150U);
  EXPECT_GT(report.duplicated, 150U);
  EXPECT_GT(report.reordered, 150U);
  EXPECT_EQ(report.send_failures, 0U);
}

TEST(Simulator, DeterministicFaultsLandWhereAsked) {
  SimConfig config = config_with("1:q");
  config.faults.drop_every = 10;      // frames 9, 19
  config.faults.duplicate_every = 7;  // frames 6, 13
  config.faults.reorder_every = 4;    // frames 3, 7, 11, 15 (not 19: dropped)
  Simulator sim(config);
  CapturingSink sink;
  const SimReport report = run(sim, sink, 20);
  const Tally tally(sink);
  EXPECT_EQ(report.dropped, 2U);
  EXPECT_EQ(report.duplicated, 2U);
  EXPECT_EQ(report.reordered, 4U);
  std::vector<int> packet_numbers;
  for (const wire::StateValues& frame : tally.frames) packet_numbers.push_back(frame.packet_number);
  const std::vector<int> expected = {0, 1, 2, 4, 3, 5, 6, 6, 8, 7, 10, 12, 11, 13, 13, 14, 0, 15, 1, 2};
  EXPECT_EQ(packet_numbers, expected);
}

TEST(Simulator, RecordsEveryValidDatagramInSendOrder) {
  SimConfig config = config_with("1:q,time");
  config.faults.duplicate_every = 5;
  config.faults.corrupt_every = 3;
  config.faults.reorder_every = 7;
  Simulator sim(config);
  std::ostringstream record;
  sim.record_to(&record);
  CapturingSink sink;
  run(sim, sink, 100);
  const Tally tally(sink);

  std::istringstream lines(record.str());
  std::string line;
  std::size_t index = 0;
  while (std::getline(lines, line)) {
    ASSERT_LT(index, tally.frames.size());
    EXPECT_EQ(line, wire::to_canonical_json(tally.frames[index++]));
  }
  EXPECT_EQ(index, tally.frames.size());
  EXPECT_EQ(index, sim.report().valid);
}

TEST(Simulator, RestartBeginsTimeAndPacketNumbersAgain) {
  SimConfig config = config_with("1:time");
  config.restart_after = 20;
  Simulator sim(config);
  CapturingSink sink;
  const SimReport report = run(sim, sink, 30);
  const Tally tally(sink);
  EXPECT_EQ(report.restarts, 1U);
  EXPECT_EQ(tally.frames[19].integer(wire::Field::time), 19U);
  EXPECT_EQ(tally.frames[19].packet_number, 3);
  EXPECT_EQ(tally.frames[20].integer(wire::Field::time), 0U);
  EXPECT_EQ(tally.frames[20].packet_number, 0);
  EXPECT_EQ(tally.frames[29].packet_number, 9);
}

TEST(Simulator, PauseSilencesTheLinkWhileTheClockRuns) {
  SimConfig config = config_with("1:time");
  config.pause_after = 10;
  config.pause = 250ms;
  Simulator sim(config);
  CapturingSink sink;
  for (int i = 0; i < 9; ++i) EXPECT_EQ(sim.step(sink), 0ns);
  EXPECT_EQ(sim.step(sink), 250ms);  // the 10th frame, then silence
  EXPECT_EQ(sim.step(sink), 0ns);
  const Tally tally(sink);
  EXPECT_EQ(sim.report().pauses, 1U);
  EXPECT_EQ(tally.frames[9].integer(wire::Field::time), 9U);
  EXPECT_EQ(tally.frames[10].integer(wire::Field::time), 260U);
  EXPECT_EQ(tally.frames[10].packet_number, 10);
}

// A host too busy to keep the schedule: the stream goes on later, but the frames are those the
// robot would have sent (times k / rate, a reordering as it would have been), only the silence is new.
TEST(Simulator, AStallLeavesTheRobotsFramesAlone) {
  SimConfig config = config_with("1:time");
  config.faults.reorder_every = 5;  // frame 4 is held back for frame 5
  Simulator sim(config);
  CapturingSink sink;
  for (int i = 0; i < 5; ++i) sim.step(sink);
  sim.stall();
  sim.step(sink);
  const Tally tally(sink);
  ASSERT_EQ(tally.frames.size(), 6U);
  const std::vector<std::uint64_t> order{0, 1, 2, 3, 5, 4};
  for (std::size_t i = 0; i < order.size(); ++i) {
    EXPECT_EQ(tally.frames[i].packet_number, order[i]);
    EXPECT_EQ(tally.frames[i].integer(wire::Field::time), order[i]);
  }
  EXPECT_EQ(sim.report().stalls, 1U);
  EXPECT_EQ(sim.report().reordered, 1U);
}

TEST(Simulator, SelectionRequestReplacesTheSchedule) {
  Simulator sim(config_with("1:q"));
  CapturingSink sink;
  sim.step(sink);

  wire::Selection wanted;
  wanted.add(wire::Field::tau_J);
  wanted.add_group(5);
  std::array<std::uint8_t, wire::kSelectionRequestBytes> request{};
  ASSERT_TRUE(wire::encode_selection_request(0, wanted, request));
  EXPECT_TRUE(sim.handle_request(request));
  sim.step(sink);

  request[5] ^= 0x01;  // now the CRC is wrong
  EXPECT_FALSE(sim.handle_request(request));
  EXPECT_FALSE(sim.handle_request(std::span(request).first(3)));
  sim.step(sink);

  const Tally tally(sink);
  EXPECT_EQ(tally.frames[0].selection.data_select, (std::array<std::uint8_t, 6>{0, 0, 0x20, 0, 0, 0}));
  EXPECT_EQ(tally.frames[1].selection, wanted);
  EXPECT_EQ(tally.frames[2].selection, wanted);
  EXPECT_EQ(sim.report().selection_requests, 1U);
  EXPECT_EQ(sim.report().invalid_requests, 2U);
}

TEST(Simulator, SameSeedSameDatagrams) {
  SimConfig config = config_with("1:all");
  config.faults.corrupt = 0.3;
  config.faults.reorder = 0.1;
  CapturingSink first;
  CapturingSink second;
  Simulator a(config);
  Simulator b(config);
  run(a, first, 300);
  run(b, second, 300);
  EXPECT_EQ(first.datagrams, second.datagrams);
}

TEST(SimReport, JsonHasEveryCounterAndCategory) {
  SimReport report;
  report.sent = 10;
  report.valid = 7;
  report.invalid_count(wire::ErrorCategory::kBadCrc) = 2;
  report.invalid_count(wire::ErrorCategory::kBadValue) = 1;
  const auto json = nlohmann::json::parse(report.to_json());
  EXPECT_EQ(json["sent"], 10);
  EXPECT_EQ(json["valid"], 7);
  EXPECT_EQ(json["invalid"]["bad_crc"], 2);
  EXPECT_EQ(json["invalid"]["bad_value"], 1);
  EXPECT_EQ(json["invalid"].size(), wire::kErrorCategoryCount);
  for (const char* key : {"dropped", "duplicated", "reordered", "restarts", "pauses", "stalls",
                          "selection_requests", "invalid_requests", "send_failures", "longest_gap_us"})
    EXPECT_EQ(json[key], 0) << key;
}

}  // namespace
}  // namespace rsg::tools::sim
