#include "rsg/dds/group_filter.hpp"

#include <array>
#include <cctype>
#include <fastdds/dds/topic/IContentFilter.hpp>
#include <fastdds/dds/topic/IContentFilterFactory.hpp>
#include <optional>
#include <string>

#include "rsg/dds/detail/fastdds_compat.hpp"
#include "rsg/error.hpp"
#include "rsg/wire/field_table.hpp"

namespace rsg::dds {
namespace fdds = eprosima::fastdds::dds;
namespace {

constexpr std::size_t kEncapsulationBytes = 4;
constexpr std::size_t kGroupSelectOffset = 1;  // after packet_number (idl/RobotState.idl)
constexpr std::uint8_t kValidGroupBits = (1U << wire::kGroupCount) - 1;

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

// One filter per group mask, built once: evaluating allocates nothing and holds no state, so any
// number of readers and threads may share them.
class GroupFilter final : public fdds::IContentFilter {
 public:
  void set_groups(std::uint8_t groups) { groups_ = groups; }
  bool evaluate(const SerializedPayload& payload, const FilterSampleInfo&, const GUID_t&) const override {
    return payload_carries_groups(std::span<const std::uint8_t>(payload.data, payload.length), groups_);
  }

 private:
  std::uint8_t groups_ = 0;
};

class GroupFilterFactory final : public fdds::IContentFilterFactory {
 public:
  GroupFilterFactory() {
    for (std::size_t mask = 0; mask < filters_.size(); ++mask)
      filters_[mask].set_groups(static_cast<std::uint8_t>(mask));
  }

  ReturnCode create_content_filter(const char*, const char*, const fdds::TopicDataType*,
                                   const char* expression, const ParameterSeq& parameters,
                                   fdds::IContentFilter*& filter) override {
    // A null expression means "new parameters, same expression": these filters take none.
    if (expression == nullptr) return filter != nullptr && parameters.length() == 0 ? kOk : kBadParameter;
    const wire::Parsed<std::uint8_t> groups = parse_group_filter_expression(expression);
    if (!groups || parameters.length() != 0) return kBadParameter;
    filter = &filters_[*groups];
    return kOk;
  }

  ReturnCode delete_content_filter(const char*, fdds::IContentFilter*) override { return kOk; }

 private:
  std::array<GroupFilter, kValidGroupBits + 1> filters_;
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

void register_group_filter(fdds::DomainParticipant& participant) {
  // Stateless after construction, shared by every participant of the process; Fast DDS keeps the
  // pointer, so it lives as long as the process.
  static GroupFilterFactory factory;
  if (participant.lookup_content_filter_factory(kGroupFilterClass) != nullptr) return;
  const ReturnCode registered = participant.register_content_filter_factory(kGroupFilterClass, &factory);
  // PRECONDITION_NOT_MET: another thread registered it meanwhile.
  if (registered != kOk && participant.lookup_content_filter_factory(kGroupFilterClass) == nullptr)
    throw EnvironmentError(std::string("Fast DDS refused the content filter class ") + kGroupFilterClass);
}

}  // namespace rsg::dds
