// The command-line options of rsg/dds/discovery.hpp, the same on every rsg program. The tools' own
// glue, not rsg's API, so that CLI11 stays out of the installed headers:
//
//   rsg::dds::DiscoveryOptions discovery;
//   rsg::tools::add_discovery_options(app, discovery);
//   ...
//   rsg::dds::Participant participant(domain, profile, discovery);
#pragma once

#include <CLI/CLI.hpp>

#include "rsg/dds/discovery.hpp"

namespace rsg::tools {

inline void add_discovery_options(CLI::App& app, dds::DiscoveryOptions& options) {
  const auto each = [](std::string (*check)(const std::string&)) {
    return CLI::Validator([check](std::string& value) { return check(value); }, "", "");
  };
  app.add_option("--discovery-server", options.servers, std::string(transport::kDiscoveryServerHelp))
      ->check(each(transport::check_discovery_server));
  app.add_option("--peer", options.peers, std::string(transport::kPeerHelp))
      ->check(each(transport::check_peer));
}

}  // namespace rsg::tools
