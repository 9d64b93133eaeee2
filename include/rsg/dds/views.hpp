// Group views: readers that receive only the RobotState samples carrying the groups they need.
//
// A view on groups S delivers exactly the samples whose group_select contains every group of S
// (other groups may be present too). It is a ContentFilteredTopic whose expression is the DDS-SQL
//
//     group_present[2] = TRUE AND group_present[3] = TRUE
//
// which any DDS application can use with Fast DDS's DDSSQL filter class; rsg's own view readers
// evaluate the same expression with the group filter class (group_filter.hpp), a byte and a mask
// per sample. This library builds the view from a view profile of xml_profiles/views.xml and
// combines it with a reader QoS profile (`reader_realtime`, `reader_logger`):
//
//   rsg::dds::Participant participant(domain, "rsg_participant");
//   auto* topic = participant.robot_state_topic("robot_state");
//   rsg::dds::ViewReader joints(*participant.subscriber({"robot1"}), *topic, "view_joints",
//                          rsg::dds::kRealtimeReaderProfile, &listener);
//
// Where the filter runs: rsg's writers (the gateway's, rsg_replay's) leave it to the readers
// (leave_filtering_to_readers), so a reader's filter, rsg's or a foreign DDS-SQL one, costs its
// own process and never the gateway; every view reader receives the stream a plain reader does
// and drops what its view rejects (docs/operating.md, "Views and writer-side filtering").
#pragma once

#include <cstdint>
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/publisher/qos/DataWriterQos.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/subscriber/qos/DataReaderQos.hpp>
#include <fastdds/dds/topic/ContentFilteredTopic.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <memory>
#include <string>

#include "rsg/dds/owned.hpp"
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

/// Makes a writer with `qos` evaluate no reader's content filter: every matched reader gets every
/// sample and filters it itself. Fast DDS 2.9.1 deletes a leaving reader's filter while write()
/// may be evaluating it (a crash, fixed upstream in 3.0), and a DDS-SQL filter costs the writer a
/// DynamicData per sample per reader: neither may reach the gateway's ingress thread.
void leave_filtering_to_readers(eprosima::fastdds::dds::DataWriterQos& qos);

/// Makes `participant` evaluate the group filter class (group_filter.hpp): its view readers filter
/// with it, and its writers can filter for remote readers that use it. ViewReader calls it.
/// Idempotent.
/// @throws rsg::EnvironmentError when Fast DDS refuses the registration.
void register_group_filter(eprosima::fastdds::dds::DomainParticipant& participant);

/// Reads an XML data_reader profile's QoS, with which a reader takes plain samples in place on
/// either Fast DDS (read_plain_samples_in_place()).
/// @throws ViewError naming an unknown profile.
eprosima::fastdds::dds::DataReaderQos load_reader_qos(const eprosima::fastdds::dds::Subscriber& subscriber,
                                                      const std::string& profile);

/// A DataReader on a view of a RobotState topic, deleted with this object.
///
/// The ContentFilteredTopic "<topic>/<view>" is shared by every ViewReader of the participant on
/// that view and deleted with the last of them. A group view uses the group filter class
/// (registered on the participant here), a raw filter view DDSSQL. The subscriber and topic must outlive the
/// reader (declare the Participant first).
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
  ViewReader(const ViewReader&) = delete;
  ViewReader& operator=(const ViewReader&) = delete;

  eprosima::fastdds::dds::DataReader* get() const { return reader_.get(); }
  eprosima::fastdds::dds::DataReader* operator->() const { return reader_.get(); }
  const View& view() const { return view_; }
  /// The filtered topic the reader reads, "<topic>/<view name>".
  eprosima::fastdds::dds::ContentFilteredTopic* filtered_topic() const { return filtered_topic_.get(); }

 private:
  // Deletes the filtered topic unless another ViewReader still reads it (Fast DDS refuses then).
  struct ReleaseFilteredTopic {
    void operator()(eprosima::fastdds::dds::ContentFilteredTopic* topic) const;
  };

  View view_;
  // Declared before the reader, so that the reader goes first.
  std::unique_ptr<eprosima::fastdds::dds::ContentFilteredTopic, ReleaseFilteredTopic> filtered_topic_;
  OwnedReader reader_;
};

}  // namespace rsg::dds
