// systemd's credentials in a participant profile: under a unit with DynamicUser=, no file on disk
// belongs to the gateway's user, so its DDS Security private key cannot be a file only that user
// reads. The unit hands it over with LoadCredential=gateway.key:/etc/rsg/pki/robot1.key instead:
// systemd copies it, readable by the service alone, into the directory CREDENTIALS_DIRECTORY names,
// and the profile points there as file://${CREDENTIALS_DIRECTORY}/gateway.key, which the gateway
// expands in every property of its participant profile (Fast DDS itself expands nothing).
#pragma once

#include <string>
#include <string_view>

namespace rsg::gateway {

inline constexpr std::string_view kCredentialsVariable = "${CREDENTIALS_DIRECTORY}";

/// `value` with every ${CREDENTIALS_DIRECTORY} replaced by `directory`.
/// @throws rsg::InputError naming `where` when `value` holds the variable and `directory` is null
/// or empty (no LoadCredential= in the unit, or not started by systemd).
std::string expand_credentials_directory(std::string_view value, const char* directory,
                                         std::string_view where);

}  // namespace rsg::gateway
