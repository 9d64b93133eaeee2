// The one warning for a link that has not come up since start-up, with the numbers that tell why:
//
//   no datagram on 0.0.0.0:17000 for 10 s: is the robot sending here (its destination address and
//   port), and does no firewall drop it?
//
// or, when datagrams arrive but none is a valid frame, or all come from outside --allow-from, says
// that instead. Once a frame was valid, the link's own up/down lines take over.
#pragma once

#include <optional>
#include <string>

#include "gateway/clock.hpp"
#include "status/stats.hpp"

namespace rsg::gateway {

class NoLinkWarning {
 public:
  static constexpr Clock::duration kAfter = std::chrono::seconds(10);

  NoLinkWarning(std::string listen, Clock::time_point start) : listen_(std::move(listen)), start_(start) {}

  /// The warning, the first time it is due: `kAfter` from start-up without a valid frame.
  std::optional<std::string> due(const status::GatewayStats& stats, Clock::time_point now);

 private:
  std::string listen_;
  Clock::time_point start_;
  bool done_ = false;
};

}  // namespace rsg::gateway
