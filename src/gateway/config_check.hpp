// `rsg_gateway --check-config`: what a start would check, without starting (as `nginx -t`). The
// configuration and prepare() have been checked by then; this adds what the gateway otherwise finds
// out only once its participant exists (the writer and reader profiles) and says what it found.
#pragma once

#include <string>
#include <vector>

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
/// start (exit 1), naming the process that holds the port where /proc says. A port held by a running
/// rsg_gateway of the same `config_file` (the instance the operator is about to restart) is not a
/// failure: a restart stops that one first. Returns what the operator should read about it.
/// @throws rsg::EnvironmentError with the start's message.
std::vector<std::string> check_bindings(const GatewaySetup& setup, const std::string& config_file);

/// The files the participant profile names in its properties (DDS Security's certificates, key,
/// governance and permissions: `file://...`) exist, are readable files and hold what their property
/// needs (PEM, or signed S/MIME); Fast DDS otherwise refuses the participant with no word of which.
/// @throws rsg::InputError naming the property and the file.
void check_profile_files(const GatewayConfig& config);

/// What the gateway would do with `setup`, one item a line, for an operator to read; `notes` (of
/// check_bindings) before the verdict.
std::string describe_setup(const GatewaySetup& setup, const std::string& config_file,
                           const std::vector<std::string>& notes = {});

}  // namespace rsg::gateway
