// `rsg_gateway --check-config`: what a start would check, without starting (as `nginx -t`). The
// configuration and prepare() have been checked by then; this adds what the gateway otherwise finds
// out only once its participant exists (the writer and reader profiles) and says what it found.
#pragma once

#include <string>

#include "gateway/config.hpp"
#include "gateway/gateway.hpp"

namespace rsg::gateway {

/// Looks up the writer and reader profiles the configuration names, in the profiles prepare()
/// loaded, through a participant that is never enabled (rsg::app::check_profiles): no socket, no
/// discovery traffic.
/// @throws rsg::InputError naming the flag and the profile that is missing.
void check_entity_profiles_offline(const GatewayConfig& config);

/// What the gateway would do with `setup`, one item a line, for an operator to read.
std::string describe_setup(const GatewaySetup& setup, const std::string& config_file);

}  // namespace rsg::gateway
