// The DDS options of every rsg program that creates a participant (rsg_echo, rsg_record,
// rsg_replay, rsg_view; rsg_gateway's keys read the same way), checked before anything is created:
//
// --profiles is repeatable and takes a comma-separated list, each item an XML file or a directory
// of them, loaded in the order given; none given: rsg's own profiles (default_profiles_dir()).
// Topic and partition names are checked as they are parsed (dds_name), and the profiles that
// --qos, --view or --writer-profile name are looked up once the XML is loaded (check_profiles), so
// that the message names the flag and nothing has started yet.
#pragma once

#include <CLI/CLI.hpp>
#include <algorithm>
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/domain/qos/DomainParticipantQos.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/publisher/qos/DataWriterQos.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/subscriber/qos/DataReaderQos.hpp>
#include <initializer_list>
#include <string>
#include <vector>

#include "rsg/dds/fastdds.hpp"
#include "rsg/dds/profiles.hpp"
#include "rsg/error.hpp"

namespace rsg::app {

/// A topic or partition name: no control character (a newline would split the log and status
/// lines that show it); `may_be_empty` for the names where "" means "none".
inline CLI::Validator dds_name(bool may_be_empty) {
  return CLI::Validator(
      [may_be_empty](const std::string& name) {
        if (name.empty() && !may_be_empty) return std::string("must not be empty");
        if (std::ranges::any_of(name, [](unsigned char c) { return c < 0x20 || c == 0x7f; }))
          return std::string("must not contain control characters");
        return std::string();
      },
      "", "");
}

inline void add_profile_options(CLI::App& app, std::vector<std::string>& profiles,
                                std::string& participant_profile,
                                const std::string& participant_help = "XML participant profile") {
  app.add_option("--profiles", profiles,
                 "XML profile file or directory; repeat or separate with commas to load several, in order "
                 "(e.g. rsg's profiles and a secure participant profile)")
      ->delimiter(',')
      ->allow_extra_args(false)  // `--profiles a.xml FILE`: FILE stays the tool's positional argument
      ->check(
          [](const std::string& path) { return path.empty() ? std::string("an empty path") : std::string(); })
      ->default_str(dds::default_profiles_dir().string());
  app.add_option("--participant-profile", participant_profile, participant_help)
      ->check([](const std::string& name) {
        return name.empty() ? std::string("must not be empty") : std::string();
      })
      ->capture_default_str();
}

/// Loads what --profiles names and checks that --participant-profile is one of its profiles.
/// @throws rsg::InputError naming the flag and the rejected file or the unknown profile.
inline void load_profile_options(const std::vector<std::string>& profiles,
                                 const std::string& participant_profile) {
  try {
    if (profiles.empty()) dds::load_profiles(dds::default_profiles_dir());
    for (const auto& file_or_dir : profiles) dds::load_profiles(std::filesystem::path(file_or_dir));
  } catch (const InputError& error) {
    throw InputError(std::string("--profiles: ") + error.what());
  }
  eprosima::fastdds::dds::DomainParticipantQos unused;
  if (eprosima::fastdds::dds::DomainParticipantFactory::get_instance()->get_participant_qos_from_profile(
          participant_profile, unused) != dds::kOk) {
    std::string where;
    for (const auto& file_or_dir : profiles) where += (where.empty() ? "" : ", ") + file_or_dir;
    throw InputError("--participant-profile: no participant profile named '" + participant_profile + "' in " +
                     (where.empty() ? dds::default_profiles_dir().string() : where));
  }
}

/// A profile a flag names, to look up in the loaded XML.
struct NamedProfile {
  const char* flag;  ///< "--qos"
  enum class Kind { kDataWriter, kDataReader } kind;
  std::string name;  ///< "" : not given, nothing to look up
};

/// Looks each profile up through a participant that is never enabled (Fast DDS finds writer and
/// reader profiles only through a publisher or subscriber): no socket, no discovery traffic. Call it
/// after load_profile_options().
/// @throws rsg::InputError naming the flag of the first profile that is not defined,
/// rsg::EnvironmentError when Fast DDS refuses the disabled entities.
inline void check_profiles(std::initializer_list<NamedProfile> profiles) {
  namespace fdds = eprosima::fastdds::dds;
  auto* factory = fdds::DomainParticipantFactory::get_instance();
  fdds::DomainParticipantFactoryQos factory_qos;
  factory->get_qos(factory_qos);
  const fdds::DomainParticipantFactoryQos autoenabling = factory_qos;
  factory_qos.entity_factory().autoenable_created_entities = false;
  factory->set_qos(factory_qos);
  fdds::DomainParticipant* participant = factory->create_participant(0, fdds::PARTICIPANT_QOS_DEFAULT);
  factory->set_qos(autoenabling);  // the program's own participant is created enabled, as always
  if (participant == nullptr)
    throw EnvironmentError("Fast DDS refused a disabled participant to look profiles up");
  const auto lookup = [participant](const NamedProfile& profile) {
    if (profile.kind == NamedProfile::Kind::kDataWriter) {
      fdds::DataWriterQos qos;
      fdds::Publisher* publisher = participant->create_publisher(fdds::PUBLISHER_QOS_DEFAULT);
      return publisher != nullptr &&
             publisher->get_datawriter_qos_from_profile(profile.name, qos) == dds::kOk;
    }
    fdds::DataReaderQos qos;
    fdds::Subscriber* subscriber = participant->create_subscriber(fdds::SUBSCRIBER_QOS_DEFAULT);
    return subscriber != nullptr &&
           subscriber->get_datareader_qos_from_profile(profile.name, qos) == dds::kOk;
  };
  const NamedProfile* missing = nullptr;
  for (const NamedProfile& profile : profiles)
    if (!profile.name.empty() && !lookup(profile)) {
      missing = &profile;
      break;
    }
  participant->delete_contained_entities();
  factory->delete_participant(participant);
  if (missing != nullptr)
    throw InputError(std::string(missing->flag) + ": no " +
                     (missing->kind == NamedProfile::Kind::kDataWriter ? "data_writer" : "data_reader") +
                     " profile named '" + missing->name + "' in the loaded XML (--profiles)");
}

}  // namespace rsg::app
