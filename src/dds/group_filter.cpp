#include "rsg/dds/group_filter.hpp"

#include <cctype>
#include <optional>
#include <string>

#include "rsg/wire/field_table.hpp"

namespace rsg::dds {
namespace {

constexpr std::size_t kEncapsulationBytes = 4;
constexpr std::size_t kGroupSelectOffset = 1;  // after packet_number (idl/RobotState.idl)

// A small cursor over the expression: the grammar has four tokens, no parser library needed.
class Cursor {
 public:
  explicit Cursor(std::string_view text) : text_(text) {}
  void skip_space() {
    while (pos_ < text_.size() && std::isspace(static_cast<unsigned char>(text_[pos_]))) ++pos_;
  }
  bool at_end() {
    skip_space();
    return pos_ == text_.size();
  }
  // Consumes `word` (case-insensitively) when it comes next.
  bool take(std::string_view word) {
    skip_space();
    if (text_.size() - pos_ < word.size()) return false;
    for (std::size_t i = 0; i < word.size(); ++i)
      if (std::tolower(static_cast<unsigned char>(text_[pos_ + i])) != word[i]) return false;
    pos_ += word.size();
    return true;
  }
  std::optional<unsigned> digit() {
    skip_space();
    if (pos_ == text_.size() || !std::isdigit(static_cast<unsigned char>(text_[pos_]))) return std::nullopt;
    return static_cast<unsigned>(text_[pos_++] - '0');
  }

 private:
  std::string_view text_;
  std::size_t pos_ = 0;
};

}  // namespace

wire::Parsed<std::uint8_t> parse_group_filter_expression(std::string_view expression) {
  const auto failure = [&](const char* why) {
    return wire::ParseFailure{"\"" + std::string(expression) + "\": " + why};
  };
  Cursor cursor(expression);
  std::uint8_t groups = 0;
  do {
    if (!cursor.take("group_present") || !cursor.take("[")) return failure("expected group_present[g]");
    const std::optional<unsigned> group = cursor.digit();
    if (!group || *group >= wire::kGroupCount) return failure("a group is a number from 0 to 5");
    if (!cursor.take("]") || !cursor.take("=") || !cursor.take("true"))
      return failure("expected group_present[g] = TRUE");
    groups = static_cast<std::uint8_t>(groups | (1U << *group));
  } while (cursor.take("and"));
  if (!cursor.at_end()) return failure("only conjunctions of group_present[g] = TRUE are group filters");
  return groups;
}

bool payload_carries_groups(std::span<const std::uint8_t> payload, std::uint8_t groups) noexcept {
  if (payload.size() < kEncapsulationBytes + kGroupSelectOffset + 1) return false;
  // The representation identifier, big-endian: CDR (0, 1) and final PLAIN_CDR2 (6, 7) put the first
  // member right after the header; DELIMITED_CDR2 (8, 9) puts a 4-byte length first.
  std::size_t members = kEncapsulationBytes;
  switch (payload[1] | (payload[0] << 8)) {
    case 0x0000:
    case 0x0001:
    case 0x0006:
    case 0x0007:
      break;
    case 0x0008:
    case 0x0009:
      members += 4;
      break;
    default:
      return false;
  }
  if (payload.size() <= members + kGroupSelectOffset) return false;
  return (payload[members + kGroupSelectOffset] & groups) == groups;
}

}  // namespace rsg::dds
