// Group views: readers that receive only the RobotState samples carrying the groups they need.
//
// A view on groups S delivers exactly the samples whose group_select contains every group of S
// (other groups may be present too). It is a ContentFilteredTopic with the DDS-SQL filter
//
//     group_present[2] = TRUE AND group_present[3] = TRUE
//
// which any DDS application can create itself; this library builds it from a view profile of
// xml_profiles/views.xml and combines it with a reader QoS profile (`reader_realtime`,
// `reader_logger`):
//
//   rsg::dds::Participant participant(domain, "rsg_participant");
//   auto* topic = participant.robot_state_topic("robot_state");
//   rsg::dds::ViewReader joints(*participant.subscriber({"robot1"}), *topic, "view_joints",
//                          rsg::dds::kRealtimeReaderProfile, &listener);
//
// Fast DDS evaluates the filter in the writer for remote UDP readers, so samples a view rejects
// never cross the network; for data-sharing and intra-process readers it evaluates it in the reader.
#pragma once

#include <cstdint>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/subscriber/qos/DataReaderQos.hpp>
#include <fastdds/dds/topic/ContentFilteredTopic.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <string>

#include "rsg/error.hpp"

namespace rsg::dds {

/// Property of a view profile: comma-separated group numbers that must all be present.
inline constexpr const char* kViewGroupsProperty = "rsg.view.groups";
/// Property of a view profile: a raw DDS-SQL filter expression (instead of groups).
inline constexpr const char* kViewFilterProperty = "rsg.view.filter";

/// Shipped reader QoS flavours (xml_profiles/views.xml).
inline constexpr const char* kRealtimeReaderProfile = "reader_realtime";
inline constexpr const char* kLoggerReaderProfile = "reader_logger";

/// A view profile that cannot be used: unknown, not a view, or malformed. The message names the
/// profile and says what is wrong with it.
class ViewError : public InputError {
 public:
  using InputError::InputError;
};

/// What a reader on a view receives.
struct View {
  std::string name;         ///< names the filtered topic "<topic>/<name>": the profile, or "groups_2_3"
  std::uint8_t groups = 0;  ///< group_select bits that must all be set; 0 for a raw filter
  std::string filter;       ///< the DDS-SQL filter expression

  friend bool operator==(const View&, const View&) = default;
};

/// The DDS-SQL filter "group_present[g] = TRUE AND ..." for every bit g of `groups`, ascending.
/// @throws ViewError for 0 (a filter that accepts everything is no view) or reserved bits 6, 7.
std::string group_filter_expression(std::uint8_t groups);

/// The view on `groups`, named "groups_0_2", for readers configured without a profile.
View group_view(std::uint8_t groups);

/// The view a reader profile's properties describe (`profile` only names it in errors).
/// @throws ViewError when it has neither or both of the view properties, or a bad group list.
View parse_view(const std::string& profile, const eprosima::fastdds::dds::DataReaderQos& qos);

/// Reads the view from an XML data_reader profile (load_profiles first).
/// @throws ViewError for an unknown or unusable profile.
View load_view(const eprosima::fastdds::dds::Subscriber& subscriber, const std::string& profile);

/// Reads an XML data_reader profile's QoS, with which a reader takes plain samples in place on
/// either Fast DDS (read_plain_samples_in_place()).
/// @throws ViewError naming an unknown profile.
eprosima::fastdds::dds::DataReaderQos load_reader_qos(const eprosima::fastdds::dds::Subscriber& subscriber,
                                                      const std::string& profile);

/// A DataReader on a view of a RobotState topic, deleted with this object.
///
/// The ContentFilteredTopic "<topic>/<view>" is shared by every ViewReader of the participant on
/// that view and deleted with the last of them. The subscriber and topic must outlive the reader
/// (declare the Participant first).
class ViewReader {
 public:
  /// A reader on the view `view_profile` with the QoS of `qos_profile`; an empty `qos_profile`
  /// keeps the view profile's own QoS.
  /// @throws ViewError for unusable profiles or a filter Fast DDS cannot parse.
  /// @throws rsg::EnvironmentError when Fast DDS refuses the reader.
  /// @throws std::logic_error when `subscriber` and `topic` belong to different participants.
  ViewReader(eprosima::fastdds::dds::Subscriber& subscriber, eprosima::fastdds::dds::Topic& topic,
             const std::string& view_profile, const std::string& qos_profile,
             eprosima::fastdds::dds::DataReaderListener* listener = nullptr,
             const eprosima::fastdds::dds::StatusMask& mask = eprosima::fastdds::dds::StatusMask::all());
  /// A reader on an explicit view (e.g. group_view) with the given QoS.
  ViewReader(eprosima::fastdds::dds::Subscriber& subscriber, eprosima::fastdds::dds::Topic& topic, View view,
             const eprosima::fastdds::dds::DataReaderQos& qos,
             eprosima::fastdds::dds::DataReaderListener* listener = nullptr,
             const eprosima::fastdds::dds::StatusMask& mask = eprosima::fastdds::dds::StatusMask::all());
  ~ViewReader();
  ViewReader(const ViewReader&) = delete;
  ViewReader& operator=(const ViewReader&) = delete;

  eprosima::fastdds::dds::DataReader* get() const { return reader_; }
  eprosima::fastdds::dds::DataReader* operator->() const { return reader_; }
  const View& view() const { return view_; }
  /// The filtered topic the reader reads, "<topic>/<view name>".
  eprosima::fastdds::dds::ContentFilteredTopic* filtered_topic() const { return filtered_topic_; }

 private:
  eprosima::fastdds::dds::Subscriber& subscriber_;
  View view_;
  eprosima::fastdds::dds::ContentFilteredTopic* filtered_topic_ = nullptr;
  eprosima::fastdds::dds::DataReader* reader_ = nullptr;
};

}  // namespace rsg::dds
