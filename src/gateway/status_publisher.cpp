#include "gateway/status_publisher.hpp"

#include <GatewayStatusPubSubTypes.h>
#include <spdlog/spdlog.h>

#include <fastdds/dds/publisher/DataWriter.hpp>
#include <stdexcept>

#include "dds/internal/fastdds_compat.hpp"  // rename_type
#include "gateway/entities.hpp"
#include "rsg/error.hpp"
#include "status/status_sample.hpp"

namespace rsg::gateway {
namespace fdds = eprosima::fastdds::dds;

StatusPublisher::StatusPublisher(dds::Participant& participant, const std::string& topic,
                                 const std::vector<std::string>& partitions, const std::string& profile,
                                 DataSharing data_sharing, const std::string& type_name)
    : participant_(participant) {
  publisher_ = dds::own(participant_, participant_.publisher(partitions));
  // TypeSupport takes ownership of the type object it is given.
  fdds::TypeSupport type(new GatewayStatusPubSubType());
  if (!type_name.empty()) dds::internal::rename_type(type, type_name);
  fdds::Topic* status_topic = participant_.topic(topic, type);
  writer_ =
      dds::own(*publisher_, create_writer_with_profile(*publisher_, status_topic, profile, data_sharing),
               "the GatewayStatus writer with profile '" + profile + "'");
}

StatusPublisher::~StatusPublisher() = default;  // the owners delete the writer, then the publisher

void StatusPublisher::publish(const status::GatewayStats& stats) {
  to_status_sample(stats, sample_);
  if (!dds::succeeded(writer_->write(&sample_))) spdlog::warn("could not write the gateway status");
}

}  // namespace rsg::gateway
