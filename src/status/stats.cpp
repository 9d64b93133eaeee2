#include "status/stats.hpp"

#include <fmt/format.h>

#include <nlohmann/json.hpp>
#include <numeric>

namespace rsg::status {

std::uint64_t IngressCounters::invalid_total() const {
  return std::accumulate(invalid.begin(), invalid.end(), std::uint64_t{0});
}

std::string to_json(const GatewayStats& stats) {
  nlohmann::ordered_json invalid = nlohmann::ordered_json::object();
  for (std::size_t i = 0; i < stats.ingress.invalid.size(); ++i)
    invalid[std::string(wire::to_string(category_at(i)))] = stats.ingress.invalid[i];

  const nlohmann::ordered_json json = {
      {"source", stats.source},
      {"link_up", stats.link_up},
      {"rate_hz", stats.rate_hz},
      {"frames_received", stats.ingress.received},
      {"frames_published", stats.ingress.published},
      {"publish_failed", stats.ingress.publish_failed},
      {"invalid", invalid},
      {"rejected_source", stats.ingress.rejected_source},
      {"state_readers", stats.state_readers},
      {"egress_writers", stats.egress_writers},
      {"standard_readers", stats.standard_readers},
      {"lost", stats.sequence.lost},
      {"duplicated", stats.sequence.duplicated},
      {"reordered", stats.sequence.reordered},
      {"robot_restarts", stats.sequence.restarts},
      {"out_of_sequence", stats.sequence.out_of_sequence},
      {"egress_samples", stats.egress.samples},
      {"egress_frames_sent", stats.egress.frames_sent},
      {"egress_unencodable", stats.egress.unencodable},
      {"egress_send_failed", stats.egress.send_failed},
      {"egress_request_like", stats.egress.request_like},
      {"egress_rate_limited", stats.egress.rate_limited},
      {"standard_dropped", stats.standard_dropped},
      {"ingress_delay_us", stats.ingress_delay_us},
      {"ingress_delay_max_us", stats.ingress_delay_max_us},
  };
  return json.dump();
}

std::string format_invalid(const InvalidCounts& counts) {
  std::string text;
  for (std::size_t i = 0; i < counts.size(); ++i) {
    if (counts[i] == 0) continue;
    if (!text.empty()) text += ' ';
    text += fmt::format("{}={}", wire::to_string(category_at(i)), counts[i]);
  }
  return text;
}

std::string summary_line(const GatewayStats& stats) {
  const auto& in = stats.ingress;
  std::string line = fmt::format(
      "link {} from {} at {:.1f} Hz; received {} published {} invalid {}{}{}{} rejected_source {}; "
      "lost {} duplicated {} reordered {} robot_restarts {} out_of_sequence {}",
      stats.link_up ? "up" : "down", stats.source.empty() ? "(nobody yet)" : stats.source, stats.rate_hz,
      in.received, in.published, in.invalid_total(), in.invalid_total() ? " (" : "",
      format_invalid(in.invalid), in.invalid_total() ? ")" : "", in.rejected_source, stats.sequence.lost,
      stats.sequence.duplicated, stats.sequence.reordered, stats.sequence.restarts,
      stats.sequence.out_of_sequence);
  if (in.publish_failed) line += fmt::format("; publish_failed {}", in.publish_failed);
  const auto& out = stats.egress;
  if (out.samples || out.unencodable)
    line += fmt::format(
        "; egress samples {} sent {} unencodable {} send_failed {} request_like {} rate_limited {}",
        out.samples, out.frames_sent, out.unencodable, out.send_failed, out.request_like, out.rate_limited);
  if (stats.standard_dropped) line += fmt::format("; standard_dropped {}", stats.standard_dropped);
  line +=
      fmt::format("; ingress delay {} us (max {} us)", stats.ingress_delay_us, stats.ingress_delay_max_us);
  return line;
}

}  // namespace rsg::status
