// The group filter class on arbitrary input: a reader evaluates it on every serialized sample that
// arrives, and a writer that knows the class parses the expressions remote readers announce.
//  - parse_group_filter_expression(): never crashes; what it accepts is a mask of groups 0..5, and
//    the canonical expression of that mask (as views.cpp writes it) parses to the same mask;
//  - payload_carries_groups(): never reads outside the payload, and says yes only for a payload
//    long enough to hold group_select whose bits cover the mask.
#include <cstdint>
#include <span>
#include <string>
#include <string_view>

#include "rsg/dds/group_filter.hpp"
#include "tests/fuzz/fuzz_check.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::span<const std::uint8_t> bytes(data, size);
  const auto parsed =
      rsg::dds::parse_group_filter_expression(std::string_view(reinterpret_cast<const char*>(data), size));
  if (parsed) {
    FUZZ_REQUIRE(*parsed != 0 && *parsed < 64);
    std::string canonical;
    for (unsigned group = 0; group < 6; ++group)
      if ((*parsed >> group) & 1U)
        canonical += (canonical.empty() ? "" : " AND ") + std::string("group_present[") + char('0' + group) +
                     "] = TRUE";
    const auto again = rsg::dds::parse_group_filter_expression(canonical);
    FUZZ_REQUIRE(again && *again == *parsed);
  } else {
    FUZZ_REQUIRE(!parsed.error().empty());
  }
  if (size >= 1) {
    const std::uint8_t mask = static_cast<std::uint8_t>(data[0] & 0x3f);
    const bool carries = rsg::dds::payload_carries_groups(bytes.subspan(1), mask);
    if (carries) FUZZ_REQUIRE(size - 1 >= 6);
  }
  return 0;
}
