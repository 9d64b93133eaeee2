// PublicationOrder: what rsg_record writes is each writer's samples in sequence order, whatever order
// they arrived in, and the counts say what could not be placed.
#include "app/recording_order.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <vector>

namespace rsg::app {
namespace {

using namespace std::chrono_literals;

constexpr std::uint64_t kMs = 1'000'000;
constexpr std::uint16_t kState = 1, kStatus = 2;
const PublicationOrder::WriterId kWriterA{1}, kWriterB{2};

struct Recorder {
  PublicationOrder order{500ms};
  std::vector<std::pair<std::uint16_t, std::uint64_t>> written;  // channel, sequence

  void add(std::uint64_t sequence, std::uint64_t received_ms,
           const PublicationOrder::WriterId& writer = kWriterA, std::uint16_t channel = kState,
           bool contiguous = true) {
    const std::uint8_t byte = static_cast<std::uint8_t>(sequence);
    order.add(writer, contiguous, std::span<const std::uint8_t>(&byte, 1),
              {.channel = channel,
               .sequence = sequence,
               .log_time = received_ms * kMs,
               .publish_time = 0,
               .payload = {}});
  }
  void release(std::uint64_t now_ms) {
    order.release(now_ms * kMs, [this](const PublicationOrder::Sample& sample) {
      EXPECT_EQ(sample.payload, std::vector<std::uint8_t>{static_cast<std::uint8_t>(sample.sequence)});
      written.emplace_back(sample.channel, sample.sequence);
    });
  }
  std::vector<std::uint64_t> sequences() const {
    std::vector<std::uint64_t> out;
    for (const auto& [channel, sequence] : written)
      if (channel == kState) out.push_back(sequence);
    return out;
  }
};

std::vector<std::uint64_t> range(std::uint64_t first, std::uint64_t last) {
  std::vector<std::uint64_t> out;
  for (std::uint64_t s = first; s <= last; ++s) out.push_back(s);
  return out;
}

// What a recorder joining a running gateway on a loaded host got: 70 live samples, then the 108
// before them from the writer's history.
TEST(PublicationOrder, HistoryArrivingAfterLiveSamplesIsWrittenBeforeThem) {
  Recorder r;
  for (std::uint64_t s = 1109; s < 1179; ++s) r.add(s, 1000 + (s - 1109));
  r.release(1200);
  EXPECT_TRUE(r.written.empty()) << "nothing is due before it has waited the hold";
  for (std::uint64_t s = 1001; s < 1109; ++s) r.add(s, 1075);
  for (std::uint64_t s = 1179; s <= 1700; ++s) r.add(s, 1000 + (s - 1109));
  r.release(1520);
  // Due: everything received by 1020 ms, and what precedes it in sequence.
  EXPECT_EQ(r.sequences(), range(1001, 1129));
  r.order.release_all(
      [&r](const PublicationOrder::Sample& s) { r.written.emplace_back(s.channel, s.sequence); });
  EXPECT_EQ(r.sequences(), range(1001, 1700));
  const auto counts = r.order.counts(kState);
  EXPECT_EQ(counts.gaps, 0u);
  EXPECT_EQ(counts.before_start, 0u);
  EXPECT_EQ(counts.late, 0u);
  EXPECT_EQ(r.order.held(), 0u);
}

TEST(PublicationOrder, HistoryArrivingAfterTheHoldIsLeftOutNotWrittenOutOfOrder) {
  Recorder r;
  for (std::uint64_t s = 200; s < 300; ++s) r.add(s, s);
  r.release(1000);
  EXPECT_EQ(r.sequences(), range(200, 299));
  r.add(150, 1000);  // from before the first written sample
  r.release(2000);
  EXPECT_EQ(r.sequences(), range(200, 299));
  EXPECT_EQ(r.order.counts(kState).before_start, 1u);
  EXPECT_EQ(r.order.counts(kState).gaps, 0u);
}

// At the first release, what lies below the last hole is history still trickling in: the recording
// starts with the unbroken run after it.
TEST(PublicationOrder, AContiguousStreamStartsAfterTheLastHoleOfWhatHasArrived) {
  Recorder r;
  for (std::uint64_t s : {10, 11, 12, 20, 21, 22, 23}) r.add(s, 100);
  r.release(600);
  EXPECT_EQ(r.sequences(), range(20, 23));
  EXPECT_EQ(r.order.counts(kState).before_start, 3u);
  EXPECT_EQ(r.order.counts(kState).gaps, 0u);
}

TEST(PublicationOrder, AHoleAfterTheStartIsAGapAndItsLateSampleIsCountedNotWritten) {
  Recorder r;
  for (std::uint64_t s = 1; s <= 10; ++s) r.add(s, s);
  r.release(600);
  for (std::uint64_t s : {11, 12, 14, 15}) r.add(s, 600 + s);
  r.release(700);  // 13 may still come
  EXPECT_EQ(r.sequences(), range(1, 10));
  r.release(1200);  // 14 has waited the hold: 13 is given up
  EXPECT_EQ(r.sequences(), (std::vector<std::uint64_t>{1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 14, 15}));
  r.add(13, 1300);
  r.release(2000);
  const auto counts = r.order.counts(kState);
  EXPECT_EQ(counts.gaps, 1u);
  EXPECT_EQ(counts.late, 1u);
  EXPECT_EQ(r.sequences().size(), 14u);
}

TEST(PublicationOrder, ARepairWithinTheHoldTakesItsPlace) {
  Recorder r;
  for (std::uint64_t s = 1; s <= 5; ++s) r.add(s, s);
  r.release(600);
  for (std::uint64_t s : {6, 8, 9}) r.add(s, 600 + s);
  r.add(7, 900);  // repaired 300 ms later
  r.release(2000);
  EXPECT_EQ(r.sequences(), range(1, 9));
  EXPECT_EQ(r.order.counts(kState).gaps, 0u);
}

// A view filters on purpose: its holes are neither gaps nor a reason to cut the start.
TEST(PublicationOrder, AViewsHolesAreNotCounted) {
  Recorder r;
  for (std::uint64_t s : {3, 6, 9, 12}) r.add(s, s, kWriterA, kState, false);
  r.release(1000);
  EXPECT_EQ(r.sequences(), (std::vector<std::uint64_t>{3, 6, 9, 12}));
  EXPECT_EQ(r.order.counts(kState).gaps, 0u);
  EXPECT_EQ(r.order.counts(kState).before_start, 0u);
}

TEST(PublicationOrder, WritersAndChannelsAreMergedByLogTimeEachInItsOwnOrder) {
  Recorder r;
  r.add(1, 10, kWriterA);
  r.add(50, 11, kWriterB);
  r.add(7, 12, kWriterA, kStatus);
  r.add(2, 13, kWriterA);
  r.add(51, 14, kWriterB);
  r.add(1, 15, kWriterB);  // below a hole in writer B's stream: its start is the run 50..51
  r.release(1000);
  const std::vector<std::pair<std::uint16_t, std::uint64_t>> expected{
      {kState, 1}, {kState, 50}, {kStatus, 7}, {kState, 2}, {kState, 51}};
  EXPECT_EQ(r.written, expected);
  EXPECT_EQ(r.order.counts(kState).before_start, 1u);
}

TEST(PublicationOrder, TheSameSampleTwiceIsWrittenOnce) {
  Recorder r;
  r.add(1, 1);
  r.add(1, 2);
  r.add(2, 3);
  r.release(1000);
  r.add(2, 1001);
  r.release(2000);
  EXPECT_EQ(r.sequences(), range(1, 2));
  EXPECT_EQ(r.order.counts(kState).late, 0u);
  EXPECT_EQ(r.order.counts(kState).before_start, 0u);
}

}  // namespace
}  // namespace rsg::app
