#include "rsg/dds/views.hpp"

#include <fastdds/dds/domain/DomainParticipant.hpp>

#include "dds/internal/fastdds_compat.hpp"
#include "rsg/dds/group_filter.hpp"
#include "rsg/error.hpp"
#include "rsg/wire/field_table.hpp"
#include "rsg/wire/selection.hpp"

namespace rsg::dds {
namespace fdds = eprosima::fastdds::dds;
namespace {

using dds::rtps::PropertyPolicyHelper;

constexpr std::uint8_t kValidGroupBits = (1U << wire::kGroupCount) - 1;

void check_groups(std::uint8_t groups) {
  if (groups == 0) throw ViewError("a view needs at least one group");
  if ((groups & ~kValidGroupBits) != 0)
    throw ViewError("group bits 6 and 7 are reserved: a view can only ask for groups 0..5");
}

// Reuses the participant's filtered topic of that name, so that several readers of one view
// share it; a name already taken by something else is a configuration error, not a reuse.
fdds::ContentFilteredTopic* find_or_create_filtered_topic(fdds::DomainParticipant& participant,
                                                          fdds::Topic& topic, const std::string& name,
                                                          const View& view) {
  const std::string& filter = view.filter;
  fdds::TopicDescription* existing = participant.lookup_topicdescription(name);
  if (existing == nullptr) {
    fdds::ContentFilteredTopic* created = nullptr;
    if (view.groups != 0) {
      register_group_filter(participant);
      created = participant.create_contentfilteredtopic(name, &topic, filter, {}, kGroupFilterClass);
    } else {
      created = participant.create_contentfilteredtopic(name, &topic, filter, {});
    }
    if (created == nullptr)
      throw ViewError("cannot create the filtered topic '" + name + "' with filter \"" + filter +
                      "\" (a DDS-SQL expression over RobotState's members?)");
    return created;
  }
  auto* filtered = dynamic_cast<fdds::ContentFilteredTopic*>(existing);
  if (filtered == nullptr || filtered->get_related_topic() != &topic ||
      filtered->get_filter_expression() != filter)
    throw ViewError("the topic name '" + name +
                    "' is already used with a different meaning in this participant");
  return filtered;
}

}  // namespace

std::string group_filter_expression(std::uint8_t groups) {
  check_groups(groups);
  std::string expression;
  for (std::size_t group = 0; group < wire::kGroupCount; ++group) {
    if (((groups >> group) & 1U) == 0) continue;
    if (!expression.empty()) expression += " AND ";
    expression += "group_present[" + std::to_string(group) + "] = TRUE";
  }
  return expression;
}

View group_view(std::uint8_t groups) {
  View view{.name = "groups", .groups = groups, .filter = group_filter_expression(groups)};
  for (std::size_t group = 0; group < wire::kGroupCount; ++group)
    if ((groups >> group) & 1U) view.name += "_" + std::to_string(group);
  return view;
}

View parse_view(const std::string& profile, const fdds::DataReaderQos& qos) {
  const std::string* groups = PropertyPolicyHelper::find_property(qos.properties(), kViewGroupsProperty);
  const std::string* filter = PropertyPolicyHelper::find_property(qos.properties(), kViewFilterProperty);
  const std::string where = "profile '" + profile + "': ";
  if (groups == nullptr && filter == nullptr)
    throw ViewError(where + "not a view: it has no property " + kViewGroupsProperty + " or " +
                    kViewFilterProperty);
  if (groups != nullptr && filter != nullptr)
    throw ViewError(where + "has both " + kViewGroupsProperty + " and " + kViewFilterProperty +
                    "; a view is one or the other");
  if (filter != nullptr) {
    if (filter->empty()) throw ViewError(where + kViewFilterProperty + " is empty");
    return View{.name = profile, .groups = 0, .filter = *filter};
  }
  const wire::Parsed<std::uint8_t> mask = wire::parse_group_mask(*groups);
  if (!mask) throw ViewError(where + kViewGroupsProperty + " = \"" + *groups + "\": " + mask.error());
  return View{.name = profile, .groups = *mask, .filter = group_filter_expression(*mask)};
}

void leave_filtering_to_readers(fdds::DataWriterQos& qos) {
  // DataWriterImpl filters only with a reader filter slot to fill; with none it keeps no filter.
  qos.writer_resource_limits().reader_filters_allocation.initial = 0;
  qos.writer_resource_limits().reader_filters_allocation.maximum = 0;
}

fdds::DataReaderQos load_reader_qos(const fdds::Subscriber& subscriber, const std::string& profile) {
  fdds::DataReaderQos qos;
  if (subscriber.get_datareader_qos_from_profile(profile, qos) != rsg::dds::kOk)
    throw ViewError("profile '" + profile + "': no such data_reader profile (are the XML profiles loaded?)");
  internal::read_plain_samples_in_place(qos);
  return qos;
}

View load_view(const fdds::Subscriber& subscriber, const std::string& profile) {
  return parse_view(profile, load_reader_qos(subscriber, profile));
}

ViewReader::ViewReader(fdds::Subscriber& subscriber, fdds::Topic& topic, const std::string& view_profile,
                       const std::string& qos_profile, fdds::DataReaderListener* listener,
                       const fdds::StatusMask& mask)
    : ViewReader(subscriber, topic, load_view(subscriber, view_profile),
                 load_reader_qos(subscriber, qos_profile.empty() ? view_profile : qos_profile), listener,
                 mask) {}

ViewReader::ViewReader(fdds::Subscriber& subscriber, fdds::Topic& topic, View view,
                       const fdds::DataReaderQos& qos, fdds::DataReaderListener* listener,
                       const fdds::StatusMask& mask)
    : view_(std::move(view)) {
  fdds::DomainParticipant& participant = *topic.get_participant();
  if (subscriber.get_participant() != &participant)
    throw std::logic_error("ViewReader: subscriber and topic belong to different participants");
  const std::string name = topic.get_name() + "/" + view_.name;
  filtered_topic_.reset(find_or_create_filtered_topic(participant, topic, name, view_));
  reader_ = own(subscriber, subscriber.create_datareader(filtered_topic_.get(), qos, listener, mask),
                "a reader on '" + name + "' (inconsistent reader QoS?)");
}

void ViewReader::ReleaseFilteredTopic::operator()(fdds::ContentFilteredTopic* topic) const {
  // Fast DDS refuses (PRECONDITION_NOT_MET) while another reader still uses the filtered topic;
  // the last ViewReader on the view deletes it.
  topic->get_participant()->delete_contentfilteredtopic(topic);
}

}  // namespace rsg::dds
