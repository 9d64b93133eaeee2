// What discovery has announced of the other participants' writers (topic, type, partitions), so
// that a reader that matches no writer can say what it could see instead:
//
//   rsg::dds::WriterDirectory writers;  // before the participant: it must outlive it
//   rsg::dds::Participant participant(domain, profile, discovery, writers.listener());
//   ...
//   for (const std::string& line : rsg::dds::explain_no_writer(wanted, writers.writers())) ...
//
// A participant sees only its own domain: a writer on another domain never shows up here.
#pragma once

#include <cstddef>
#include <memory>
#include <string>
#include <vector>

namespace eprosima::fastdds::dds {
class DomainParticipant;
class DomainParticipantListener;
}  // namespace eprosima::fastdds::dds

namespace rsg::dds {

/// A writer of another participant, as discovery announced it.
struct DiscoveredWriter {
  std::string topic;
  std::string type;
  std::vector<std::string> partitions;  ///< empty: the default partition
  /// The writer's participant (its GUID prefix as text): two writers of one participant are one
  /// program, of two participants two (another robot's gateway, a replay).
  std::string participant = {};  // defaulted: the lists of tests name three members

  friend bool operator==(const DiscoveredWriter&, const DiscoveredWriter&) = default;
};

class WriterDirectory {
 public:
  WriterDirectory();
  ~WriterDirectory();
  WriterDirectory(const WriterDirectory&) = delete;
  WriterDirectory& operator=(const WriterDirectory&) = delete;

  /// The listener to create the participant with (it must not outlive this object). It takes
  /// discovery's callbacks only: give it StatusMask::none().
  eprosima::fastdds::dds::DomainParticipantListener* listener();

  /// The writers known now, in the order they were discovered; removed ones are gone. Thread-safe.
  std::vector<DiscoveredWriter> writers() const;

 private:
  class Listener;
  std::unique_ptr<Listener> listener_;
};

/// What a reader looks for.
struct WantedWriter {
  int domain = 0;
  std::string topic;
  std::string type;
  std::vector<std::string> partitions;  ///< empty: the default partition
};

/// The lines that tell a user why a reader of `wanted` has no writer: what it looks for, and the
/// writers of that topic (or of a RobotState type) visible in other partitions or under another
/// type, each with the option that would match it; or that nothing is visible on the domain at all.
std::vector<std::string> explain_no_writer(const WantedWriter& wanted,
                                           const std::vector<DiscoveredWriter>& seen);

/// The warning for a reader of `wanted` matched by writers of more than one participant in one
/// partition: more than one robot (gateway) writes the topic there, and the reader gets their
/// samples interleaved. Empty when every partition that `wanted` matches has one participant's
/// writers (a reader of several partitions, one robot in each, is not mixed).
std::vector<std::string> explain_mixed_writers(const WantedWriter& wanted,
                                               const std::vector<DiscoveredWriter>& seen);

/// How many writers of `topic` whose partitions match `partitions` belong to participants other
/// than `own_participant` (a gateway's: another writer of its state topic in its partition).
std::size_t count_other_writers(const std::string& topic, const std::vector<std::string>& partitions,
                                const std::string& own_participant,
                                const std::vector<DiscoveredWriter>& seen);

/// The GUID prefix of `participant` as DiscoveredWriter::participant spells it.
std::string participant_key(const eprosima::fastdds::dds::DomainParticipant& participant);

/// "partition 'robot1'", "partitions 'a', 'b'", "the default partition".
std::string describe_partitions(const std::vector<std::string>& partitions);

}  // namespace rsg::dds
