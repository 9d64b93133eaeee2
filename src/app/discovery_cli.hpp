// The command-line options of rsg/dds/discovery.hpp, the same on every rsg program. The tools' own
// glue, not rsg's API, so that CLI11 stays out of the installed headers:
//
//   rsg::dds::DiscoveryOptions discovery;
//   rsg::app::add_discovery_options(app, discovery);
//   ...
//   rsg::dds::Participant participant(domain, profile, discovery);
#pragma once

#include <CLI/CLI.hpp>

#include "rsg/dds/discovery.hpp"

namespace rsg::app {

inline void add_discovery_options(CLI::App& app, dds::DiscoveryOptions& options) {
  // CLI11 takes "" for a good value: exactly what a failed Parsed says, and a good one.
  const auto each = [](auto parse) {
    return CLI::Validator([parse](std::string& value) { return parse(value).error(); }, "", "");
  };
  app.add_option("--discovery-server", options.servers, std::string(transport::kDiscoveryServerHelp))
      ->check(each(transport::parse_discovery_server));
  app.add_option("--peer", options.peers, std::string(transport::kPeerHelp))
      ->check(each(transport::parse_peer));
}

}  // namespace rsg::app
