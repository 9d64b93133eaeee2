// A stream of RobotState samples whose group_select runs through every subset of the six groups,
// so that every view meets samples with exactly its groups, more, some of them, and none.
#pragma once

#include <fastdds/dds/core/condition/StatusCondition.hpp>
#include <fastdds/dds/core/condition/WaitSet.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <random>
#include <vector>

#include "rsg/dds/fastdds.hpp"
#include "rsg/wire/field_table.hpp"
#include "rsg/wire/state_values.hpp"
#include "tests/support/random_state.hpp"

namespace rsg::test {

inline constexpr std::uint8_t kAllGroupSubsets = 1U << wire::kGroupCount;

/// Sample i selects every field of the groups of bit pattern i % 64; values are random, and
/// robot_mode is i % 7 so that raw filters on it have something to select.
inline std::vector<wire::StateValues> mixed_stream(std::size_t count) {
  std::mt19937_64 rng(42);
  std::vector<wire::StateValues> stream;
  for (std::size_t i = 0; i < count; ++i) {
    wire::StateValues values = random_state(rng);
    wire::Selection selection;
    for (std::size_t group = 0; group < wire::kGroupCount; ++group)
      if (((i % kAllGroupSubsets) >> group) & 1U) selection.add_group(group);
    values.selection = selection;
    values.packet_number = static_cast<std::uint8_t>(i % 16);
    values.set_integer(wire::Field::robot_mode, i % 7);
    // Clear what the new selection does not carry, as a decoded frame would have it.
    wire::StateValues carried;
    carried.packet_number = values.packet_number;
    carried.selection = selection;
    for (const wire::FieldInfo& field : wire::kFields) {
      if (!selection.contains(field.id())) continue;
      if (field.type == wire::ElementType::kFloat64) {
        const auto from = values.doubles(field.id());
        std::copy(from.begin(), from.end(), carried.doubles(field.id()).begin());
      } else {
        carried.set_integer(field.id(), values.integer(field.id()));
      }
    }
    stream.push_back(carried);
  }
  return stream;
}

/// Blocks until `writer` has matched `readers` readers; false if that takes longer than a minute
/// (a guard against hanging, not a performance threshold).
inline bool wait_for_matched_readers(eprosima::fastdds::dds::DataWriter& writer, int readers) {
  namespace fdds = eprosima::fastdds::dds;
  fdds::StatusCondition& condition = writer.get_statuscondition();
  condition.set_enabled_statuses(fdds::StatusMask::publication_matched());
  fdds::WaitSet waitset;
  waitset.attach_condition(condition);
  fdds::PublicationMatchedStatus status;
  for (int waits = 0; waits < 60; ++waits) {
    writer.get_publication_matched_status(status);
    if (status.current_count >= readers) return status.current_count == readers;
    fdds::ConditionSeq triggered;
    waitset.wait(triggered, rsg::dds::Duration(1, 0));
  }
  return false;
}

}  // namespace rsg::test
