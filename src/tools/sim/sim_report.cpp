#include "tools/sim/sim_report.hpp"

#include <nlohmann/json.hpp>
#include <numeric>

namespace rsg::tools::sim {

std::uint64_t SimReport::invalid_total() const {
  return std::accumulate(invalid.begin(), invalid.end(), std::uint64_t{0});
}

std::string SimReport::to_json() const {
  nlohmann::ordered_json invalid_by_category = nlohmann::ordered_json::object();
  for (std::size_t i = 0; i < invalid.size(); ++i)
    invalid_by_category[std::string(wire::kErrorCategoryNames[i + 1])] = invalid[i];
  const nlohmann::ordered_json report = {
      {"sent", sent},
      {"valid", valid},
      {"dropped", dropped},
      {"duplicated", duplicated},
      {"reordered", reordered},
      {"invalid", invalid_by_category},
      {"restarts", restarts},
      {"pauses", pauses},
      {"stalls", stalls},
      {"selection_requests", selection_requests},
      {"invalid_requests", invalid_requests},
      {"send_failures", send_failures},
      {"longest_gap_us", longest_gap_us},
  };
  return report.dump();
}

std::string SimReport::summary() const {
  std::string line = "sent " + std::to_string(sent) + " (valid " + std::to_string(valid) + ", invalid " +
                     std::to_string(invalid_total());
  for (std::size_t i = 0; i < invalid.size(); ++i)
    if (invalid[i] != 0)
      line += " " + std::string(wire::kErrorCategoryNames[i + 1]) + " " + std::to_string(invalid[i]);
  line += "), dropped " + std::to_string(dropped) + ", duplicated " + std::to_string(duplicated) +
          ", reordered " + std::to_string(reordered) + ", restarts " + std::to_string(restarts) +
          ", pauses " + std::to_string(pauses) + ", selection requests " +
          std::to_string(selection_requests) + " (invalid " + std::to_string(invalid_requests) + ")";
  if (stalls != 0) line += ", stalls " + std::to_string(stalls);
  if (send_failures != 0) line += ", send failures " + std::to_string(send_failures);
  return line;
}

}  // namespace rsg::tools::sim
