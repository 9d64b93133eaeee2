// The spec's canonical JSON form of a frame, for tools and tests (not for the hot path).
#pragma once

#include <string>
#include <string_view>

#include "rsg/wire/parsed.hpp"
#include "rsg/wire/state_values.hpp"

namespace rsg::wire {

/// Appends `values` as one canonical JSON object (no newline). Doubles use the shortest form that
/// round-trips; NaN and infinities are the strings "nan", "inf", "-inf".
void append_canonical_json(const StateValues& values, std::string& out);
std::string to_canonical_json(const StateValues& values);

/// Reads one canonical JSON object; `fields` must match the selection.
/// @return the values, or a readable failure for malformed JSON, unknown fields, wrong shapes or
/// values out of range.
Parsed<StateValues> parse_canonical_json(std::string_view text);

}  // namespace rsg::wire
