// Locating and loading the Fast DDS XML profiles that define rsg's QoS and group views.
#pragma once

#include <filesystem>

namespace rsg {

/// The directory of the project's XML profiles: $RSG_PROFILES_DIR if set, else `xml_profiles/`
/// or `share/rsg/xml_profiles/` found relative to the running binary, else the source tree.
std::filesystem::path default_profiles_dir();

/// Loads one XML file, or every *.xml file of a directory, into Fast DDS. Throws
/// std::runtime_error naming the file that Fast DDS rejected.
void load_profiles(const std::filesystem::path& file_or_dir);

}  // namespace rsg
