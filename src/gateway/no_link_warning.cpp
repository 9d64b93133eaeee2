#include "gateway/no_link_warning.hpp"

#include <fmt/format.h>

namespace rsg::gateway {

std::optional<std::string> NoLinkWarning::due(const status::GatewayStats& stats, Clock::time_point now) {
  if (done_) return std::nullopt;
  const status::IngressCounters& in = stats.ingress;
  if (in.published + in.publish_failed > 0) {  // a valid frame arrived: the link came up
    done_ = true;
    return std::nullopt;
  }
  if (now - start_ < kAfter) return std::nullopt;
  done_ = true;
  const auto seconds = std::chrono::duration_cast<std::chrono::seconds>(now - start_).count();
  if (in.received > 0)
    return fmt::format(
        "no valid frame on {} for {} s: {} datagrams arrived, every one rejected ({}): is the robot sending "
        "SEND_BUF frames as docs/protocol.md defines them? (rsg_frame decode shows why one fails)",
        listen_, seconds, in.received, status::format_invalid(in.invalid));
  if (in.rejected_source > 0)
    return fmt::format(
        "no datagram from an allowed source on {} for {} s: {} came from outside --allow-from (the "
        "warnings above name the last sender): is the robot's address in --allow-from?",
        listen_, seconds, in.rejected_source);
  return fmt::format(
      "no datagram on {} for {} s: is the robot sending here (its destination address and port), and does "
      "no firewall drop it?",
      listen_, seconds);
}

}  // namespace rsg::gateway
