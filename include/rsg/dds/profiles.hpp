// Locating and loading the Fast DDS XML profiles that define rsg's QoS and group views.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "rsg/error.hpp"

namespace rsg::dds {

/// The directory of the project's XML profiles: $RSG_PROFILES_DIR if set, else `xml_profiles/`
/// or `share/rsg/xml_profiles/` found relative to the running binary, else the source tree.
std::filesystem::path default_profiles_dir();

/// Loads one XML file, or every *.xml file of a directory, into Fast DDS.
/// @throws rsg::InputError naming the file that Fast DDS rejected, or a path without XML files.
void load_profiles(const std::filesystem::path& file_or_dir);

/// What a tool's --profiles / --participant-profile options ask for: loads each file or directory
/// (default_profiles_dir() when there is none) and checks that `participant_profile` is defined.
/// @throws rsg::InputError naming the rejected file or the unknown profile.
void load_profiles(const std::vector<std::string>& files_or_dirs, const std::string& participant_profile);

}  // namespace rsg::dds
