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

/// Binds the UDP socket of ingress and listens on the metrics address as a start would, and closes
/// them again at once: an address not on this host or a port in use fails here as it would fail the
/// start (exit 1). A running gateway of the same configuration holds them, so the check fails then.
/// @throws rsg::EnvironmentError with the start's message.
void check_bindings(const GatewaySetup& setup);

/// The files the participant profile names in its properties (DDS Security's certificates, key,
/// governance and permissions: `file://...`) exist, are readable files and hold what their property
/// needs (PEM, or signed S/MIME); Fast DDS otherwise refuses the participant with no word of which.
/// @throws rsg::InputError naming the property and the file.
void check_profile_files(const GatewayConfig& config);

/// What the gateway would do with `setup`, one item a line, for an operator to read.
std::string describe_setup(const GatewaySetup& setup, const std::string& config_file);

}  // namespace rsg::gateway
