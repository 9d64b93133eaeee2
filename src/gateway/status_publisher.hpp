// Writes GatewayStatus samples (1 Hz and on link changes; never from the per-frame path).
#pragma once

#include <GatewayStatus.h>

#include <string>
#include <vector>

#include "gateway/data_sharing.hpp"
#include "rsg/dds/owned.hpp"
#include "rsg/dds/participant.hpp"
#include "status/stats.hpp"

namespace rsg::gateway {

class StatusPublisher {
 public:
  /// @throws rsg::EnvironmentError when Fast DDS refuses the writer.
  /// `type_name` "" keeps the IDL's name (rsg::GatewayStatus), else e.g. rsg::dds::kRos2GatewayStatusType.
  StatusPublisher(dds::Participant& participant, const std::string& topic,
                  const std::vector<std::string>& partitions, const std::string& profile,
                  DataSharing data_sharing, const std::string& type_name = {});
  ~StatusPublisher();
  StatusPublisher(const StatusPublisher&) = delete;
  StatusPublisher& operator=(const StatusPublisher&) = delete;

  void publish(const status::GatewayStats& stats);

 private:
  dds::Participant& participant_;
  dds::OwnedPublisher publisher_;
  dds::OwnedWriter writer_;
  GatewayStatus sample_;
};

}  // namespace rsg::gateway
