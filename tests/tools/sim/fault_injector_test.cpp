// Every crafted corruption is rejected by the codec's decoder with exactly the category it aims at.
#include "tools/sim/fault_injector.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <string>

#include "tools/sim/panda_model.hpp"
#include "tools/sim/schedule.hpp"

namespace rsg::tools::sim {
namespace {

// Selections that exercise the edge cases: everything, one field, an empty frame, no group 5,
// group 5 only, error sets already present.
std::vector<wire::Selection> selections() {
  std::vector<wire::Selection> result;
  for (const char* items :
       {"all", "q", "g0", "g5", "g3,g4", "current_errors,last_motion_errors", "O_T_EE,time"}) {
    const wire::Parsed<wire::Selection> selection = parse_selection_items(items);
    EXPECT_TRUE(selection) << selection.error();
    result.push_back(selection ? *selection : wire::Selection{});
  }
  result.push_back(wire::Selection{});
  return result;
}

class CraftInvalid : public ::testing::TestWithParam<wire::ErrorCategory> {};

TEST_P(CraftInvalid, DecoderReportsExactlyThatCategory) {
  const wire::ErrorCategory category = GetParam();
  const PandaModel model(1);
  std::mt19937_64 random(99);
  std::array<std::uint8_t, kCraftedDatagramBytes> out{};
  for (const wire::Selection& selection : selections()) {
    wire::StateValues values;
    values.selection = selection;
    for (std::uint8_t packet_number = 0; packet_number < wire::kPacketNumberModulo; ++packet_number) {
      values.packet_number = packet_number;
      model.fill(std::chrono::milliseconds(packet_number * 31), wire::Selection::all(), values);
      // Many draws per case: each category has several ways of breaking a frame.
      for (int draw = 0; draw < 20; ++draw) {
        const std::size_t size = craft_invalid(category, values, random, out);
        ASSERT_LE(size, out.size());
        const wire::DecodeResult decoded = wire::decode(std::span(out).first(size));
        ASSERT_FALSE(decoded) << to_string(category);
        ASSERT_EQ(decoded.error().category(), category)
            << "aimed at " << to_string(category) << ", got: " << decoded.error().message();
      }
    }
  }
}

INSTANTIATE_TEST_SUITE_P(EveryCategory, CraftInvalid, ::testing::ValuesIn(all_error_categories()),
                         [](const auto& info) { return std::string(to_string(info.param)); });

TEST(FaultPlan, EveryNthRulesHitFramesNMinusOneTwoNMinusOne) {
  FaultConfig config;
  config.drop_every = 5;
  config.corrupt_every = 3;
  config.duplicate_every = 2;
  FaultPlan plan(config, 1);
  // Frames 0..9: frame 4 and 9 dropped (drop wins over the others), 2, 5, 8 corrupted, the other
  // odd frames duplicated.
  const std::vector<Fault> expected = {Fault::kNone,    Fault::kDuplicate, Fault::kCorrupt, Fault::kDuplicate,
                                       Fault::kDrop,    Fault::kCorrupt,   Fault::kNone,    Fault::kDuplicate,
                                       Fault::kCorrupt, Fault::kDrop};
  for (std::uint64_t frame = 0; frame < expected.size(); ++frame)
    EXPECT_EQ(plan.next(frame), expected[frame]) << "frame " << frame;
}

TEST(FaultPlan, ProbabilitiesGiveRoughlyTheirShare) {
  FaultConfig config;
  config.drop = 0.1;
  config.corrupt = 0.2;
  FaultPlan plan(config, 7);
  std::map<Fault, int> seen;
  for (std::uint64_t frame = 0; frame < 100000; ++frame) ++seen[plan.next(frame)];
  EXPECT_NEAR(seen[Fault::kDrop], 10000, 600);
  EXPECT_NEAR(seen[Fault::kCorrupt], 20000, 800);
  EXPECT_EQ(seen[Fault::kDuplicate], 0);
}

TEST(FaultPlan, CorruptionsCycleThroughTheChosenCategories) {
  FaultConfig config;
  config.corrupt_categories = {wire::ErrorCategory::kBadCrc, wire::ErrorCategory::kTruncated};
  FaultPlan plan(config, 1);
  EXPECT_EQ(plan.next_category(), wire::ErrorCategory::kBadCrc);
  EXPECT_EQ(plan.next_category(), wire::ErrorCategory::kTruncated);
  EXPECT_EQ(plan.next_category(), wire::ErrorCategory::kBadCrc);
}

}  // namespace
}  // namespace rsg::tools::sim
