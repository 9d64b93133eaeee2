// One log line whenever the number of writers a tool's reader is matched with changes, e.g.
// "rsg_echo: matched 1 writer of 'robot_state'".
//
// Discovery is not symmetric: a gateway may count a reader (and send to it) before that reader
// knows the gateway, and a volatile reader misses what is sent in between. The line is the
// reader's side: an operator learns the tool sees a gateway at all (a wrong domain, partition or
// security setting otherwise looks like silence), and a script or test starts the robot after it.
#pragma once

#include <spdlog/spdlog.h>

#include <cstdint>
#include <fastdds/dds/core/status/SubscriptionMatchedStatus.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <string>
#include <utility>

namespace rsg::tools {

class MatchedWriters {
 public:
  explicit MatchedWriters(std::string topic) : topic_(std::move(topic)) {}

  /// Cheap enough to call once per wake-up of the tool's loop.
  void update(eprosima::fastdds::dds::DataReader& reader) {
    eprosima::fastdds::dds::SubscriptionMatchedStatus matched;
    reader.get_subscription_matched_status(matched);
    if (matched.current_count == writers_) return;
    writers_ = matched.current_count;
    spdlog::info("matched {} {} of '{}'", writers_, writers_ == 1 ? "writer" : "writers", topic_);
  }

 private:
  std::string topic_;
  std::int32_t writers_ = 0;
};

}  // namespace rsg::tools
