// The command-line options of rsg/dds/discovery.hpp, the same on every rsg program. The tools' own
// glue, not rsg's API, so that CLI11 stays out of the installed headers:
//
//   rsg::DiscoveryOptions discovery;
//   rsg::add_discovery_options(app, discovery);
//   ...
//   rsg::Participant participant(domain, profile, discovery);
#pragma once

#include <CLI/CLI.hpp>

#include "rsg/dds/discovery.hpp"

namespace rsg {

inline void add_discovery_options(CLI::App& app, DiscoveryOptions& options) {
  const auto each = [](std::string (*check)(const std::string&)) {
    return CLI::Validator([check](std::string& value) { return check(value); }, "", "");
  };
  app.add_option("--discovery-server", options.servers, std::string(kDiscoveryServerHelp))
      ->check(each(check_discovery_server));
  app.add_option("--peer", options.peers, std::string(kPeerHelp))->check(each(check_peer));
}

}  // namespace rsg
