// The group filter class as Fast DDS sees it: a factory registered under kGroupFilterClass whose
// filters answer with payload_carries_groups (group_filter.hpp).
#include <array>
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/topic/IContentFilter.hpp>
#include <fastdds/dds/topic/IContentFilterFactory.hpp>
#include <string>

#include "dds/internal/fastdds_compat.hpp"
#include "rsg/dds/group_filter.hpp"
#include "rsg/dds/views.hpp"
#include "rsg/error.hpp"
#include "rsg/wire/field_table.hpp"

namespace rsg::dds {
namespace fdds = eprosima::fastdds::dds;
namespace {

constexpr std::uint8_t kValidGroupBits = (1U << wire::kGroupCount) - 1;

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
