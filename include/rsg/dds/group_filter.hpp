// The content filter of group views: whether a RobotState sample carries every group of a view,
// read from one byte of the serialized sample.
//
// A view's DDS-SQL expression ("group_present[2] = TRUE AND group_present[3] = TRUE") evaluated by
// Fast DDS's built-in DDSSQL filter builds a DynamicData of the whole 2 kB sample per sample and
// per reader. `group_select` is the sample's second byte in every encoding RobotState is written
// in, so this filter class (kGroupFilterClass) answers the same question with a load and a mask.
// ViewReader registers it on its participant (register_group_filter, views.hpp) and uses it for
// every group view; raw filters (`rsg.view.filter`) stay DDSSQL. This header and its source need no
// DDS (the fuzzer builds them alone).
#pragma once

#include <cstdint>
#include <span>
#include <string_view>

#include "rsg/wire/parsed.hpp"

namespace rsg::dds {

/// The filter class name group views announce; a participant must have it registered
/// (register_group_filter) to evaluate them. Peers that do not know it leave filtering to the reader.
inline constexpr const char* kGroupFilterClass = "RSG_GROUPS";

/// The group bits of a view expression as group_filter_expression() writes it: one or more
/// `group_present[g] = TRUE` joined by AND (case and spacing free), g in 0..5.
wire::Parsed<std::uint8_t> parse_group_filter_expression(std::string_view expression);

/// Whether the serialized RobotState `payload` (with its 4-byte encapsulation header) has every bit
/// of `groups` set in group_select. False for a payload too short or in an encoding RobotState is
/// never written in (parameter lists): a view must not receive a sample it cannot vouch for.
bool payload_carries_groups(std::span<const std::uint8_t> payload, std::uint8_t groups) noexcept;

}  // namespace rsg::dds
