#include "schedule.hpp"

#include <gtest/gtest.h>

namespace rsg::tools::sim {
namespace {

wire::Selection fields(std::initializer_list<wire::Field> list) {
  wire::Selection selection;
  for (wire::Field field : list) selection.add(field);
  return selection;
}

wire::Selection group(std::size_t g) {
  wire::Selection selection;
  selection.add_group(g);
  return selection;
}

TEST(Schedule, FrameCarriesTheUnionOfEntriesWhosePeriodDividesIt) {
  Schedule schedule;
  std::string error;
  ASSERT_TRUE(schedule.add("1:q,dq,time", error)) << error;
  ASSERT_TRUE(schedule.add("100:g1", error)) << error;
  ASSERT_TRUE(schedule.add("3:tau_J", error)) << error;

  const wire::Selection joints = fields({wire::Field::q, wire::Field::dq, wire::Field::time});
  EXPECT_EQ(schedule.at(0), unite(unite(joints, group(1)), fields({wire::Field::tau_J})));
  EXPECT_EQ(schedule.at(1), joints);
  EXPECT_EQ(schedule.at(3), unite(joints, fields({wire::Field::tau_J})));
  EXPECT_EQ(schedule.at(100), unite(joints, group(1)));
  EXPECT_EQ(schedule.at(300), schedule.at(0));
}

TEST(Schedule, UncoveredFrameCarriesNothing) {
  Schedule schedule;
  std::string error;
  ASSERT_TRUE(schedule.add("2:q", error));
  EXPECT_EQ(schedule.at(1), wire::Selection{});
  EXPECT_EQ(schedule.at(1).data_bytes(), 0);
}

TEST(Schedule, ConstantScheduleIsTheSameEveryFrame) {
  const Schedule schedule(wire::Selection::all());
  for (std::uint64_t frame : {0ULL, 1ULL, 17ULL, 1ULL << 40})
    EXPECT_EQ(schedule.at(frame), wire::Selection::all());
}

TEST(Schedule, ItemsMixFieldsGroupsAndAll) {
  wire::Selection selection;
  std::string error;
  ASSERT_TRUE(parse_selection_items("g0, q ,g5", selection, error)) << error;
  EXPECT_EQ(selection, unite(unite(group(0), group(5)), fields({wire::Field::q})));
  ASSERT_TRUE(parse_selection_items("all", selection, error));
  EXPECT_EQ(selection, wire::Selection::all());
}

TEST(Schedule, RejectsMalformedEntriesNamingTheCulprit) {
  for (const char* bad :
       {"q", "0:q", "x:q", "-1:q", "5:", "5:q,,dq", "5:nope", "5:g6", "5:g", "5:G1", ":q"}) {
    Schedule schedule;
    std::string error;
    EXPECT_FALSE(schedule.add(bad, error)) << bad;
    EXPECT_FALSE(error.empty()) << bad;
    EXPECT_TRUE(schedule.empty()) << bad;
  }
  std::string error;
  Schedule schedule;
  schedule.add("5:q,nope", error);
  EXPECT_NE(error.find("nope"), std::string::npos) << error;
}

}  // namespace
}  // namespace rsg::tools::sim
