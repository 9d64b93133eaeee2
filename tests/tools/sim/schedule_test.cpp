#include "tools/sim/schedule.hpp"

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

// A schedule of entries that must parse.
Schedule schedule_of(std::initializer_list<const char*> specs) {
  Schedule schedule;
  for (const char* spec : specs) {
    const wire::Parsed<Schedule::Entry> entry = parse_schedule_entry(spec);
    EXPECT_TRUE(entry) << spec << ": " << entry.error();
    if (entry) schedule.add(*entry);
  }
  return schedule;
}

TEST(Schedule, FrameCarriesTheUnionOfEntriesWhosePeriodDividesIt) {
  const Schedule schedule = schedule_of({"1:q,dq,time", "100:g1", "3:tau_J"});
  const wire::Selection joints = fields({wire::Field::q, wire::Field::dq, wire::Field::time});
  EXPECT_EQ(schedule.at(0), joints | group(1) | fields({wire::Field::tau_J}));
  EXPECT_EQ(schedule.at(1), joints);
  EXPECT_EQ(schedule.at(3), joints | fields({wire::Field::tau_J}));
  EXPECT_EQ(schedule.at(100), joints | group(1));
  EXPECT_EQ(schedule.at(300), schedule.at(0));
}

TEST(Schedule, UncoveredFrameCarriesNothing) {
  const Schedule schedule = schedule_of({"2:q"});
  EXPECT_EQ(schedule.at(1), wire::Selection{});
  EXPECT_EQ(schedule.at(1).data_bytes(), 0);
}

TEST(Schedule, ConstantScheduleIsTheSameEveryFrame) {
  const Schedule schedule(wire::Selection::all());
  for (std::uint64_t frame : {0ULL, 1ULL, 17ULL, 1ULL << 40})
    EXPECT_EQ(schedule.at(frame), wire::Selection::all());
}

TEST(Schedule, ItemsMixFieldsGroupsAndAll) {
  const wire::Parsed<wire::Selection> selection = parse_selection_items("g0, q\t,g5");
  ASSERT_TRUE(selection) << selection.error();
  EXPECT_EQ(*selection, group(0) | group(5) | fields({wire::Field::q}));
  const wire::Parsed<wire::Selection> all = parse_selection_items("all");
  ASSERT_TRUE(all) << all.error();
  EXPECT_EQ(*all, wire::Selection::all());
}

TEST(Schedule, RejectsMalformedEntriesNamingTheCulprit) {
  for (const char* bad :
       {"q", "0:q", "x:q", "-1:q", "5:", "5:q,,dq", "5:nope", "5:g6", "5:g", "5:G1", ":q"}) {
    const wire::Parsed<Schedule::Entry> entry = parse_schedule_entry(bad);
    EXPECT_FALSE(entry) << bad;
    EXPECT_FALSE(entry.error().empty()) << bad;
  }
  const wire::Parsed<Schedule::Entry> entry = parse_schedule_entry("5:q,nope");
  EXPECT_NE(entry.error().find("nope"), std::string::npos) << entry.error();
}

}  // namespace
}  // namespace rsg::tools::sim
