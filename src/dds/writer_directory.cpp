#include "rsg/dds/writer_directory.hpp"

#include <fnmatch.h>

#include <algorithm>
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantListener.hpp>
#include <map>
#include <mutex>
#include <sstream>

#include "dds/internal/fastdds_compat.hpp"

namespace rsg::dds {
namespace fdds = eprosima::fastdds::dds;

class WriterDirectory::Listener final : public fdds::DomainParticipantListener {
 public:
#if RSG_FASTDDS_MAJOR >= 3
  void on_data_writer_discovery(fdds::DomainParticipant*, rtps::WriterDiscoveryStatus reason,
                                const fdds::PublicationBuiltinTopicData& info, bool&) override {
    update(reason == rtps::WriterDiscoveryStatus::REMOVED_WRITER, info.guid, info.topic_name.to_string(),
           info.type_name.to_string(), info.partition.names());
  }
#else
  void on_publisher_discovery(fdds::DomainParticipant*, rtps::WriterDiscoveryInfo&& info) override {
    const auto& data = info.info;
    update(info.status == rtps::WriterDiscoveryInfo::REMOVED_WRITER, data.guid(),
           data.topicName().to_string(), data.typeName().to_string(), data.m_qos.m_partition.names());
  }
#endif

  std::vector<DiscoveredWriter> writers() const {
    const std::lock_guard lock(mutex_);
    std::vector<std::pair<std::uint64_t, DiscoveredWriter>> ordered;
    for (const auto& [guid, entry] : writers_) ordered.push_back(entry);
    std::sort(ordered.begin(), ordered.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    std::vector<DiscoveredWriter> result;
    for (auto& [order, writer] : ordered) result.push_back(std::move(writer));
    return result;
  }

 private:
  void update(bool removed, const rtps::GUID_t& guid, std::string topic, std::string type,
              std::vector<std::string> partitions) {
    std::ostringstream key, participant;
    key << guid;
    participant << guid.guidPrefix;
    const std::lock_guard lock(mutex_);
    if (removed) {
      writers_.erase(key.str());
      return;
    }
    auto [entry, inserted] = writers_.try_emplace(key.str(), next_, DiscoveredWriter{});
    if (inserted) ++next_;
    entry->second.second = {std::move(topic), std::move(type), std::move(partitions), participant.str()};
  }

  mutable std::mutex mutex_;
  std::map<std::string, std::pair<std::uint64_t, DiscoveredWriter>> writers_;  // by GUID
  std::uint64_t next_ = 0;
};

WriterDirectory::WriterDirectory() : listener_(std::make_unique<Listener>()) {}
WriterDirectory::~WriterDirectory() = default;

fdds::DomainParticipantListener* WriterDirectory::listener() { return listener_.get(); }

std::vector<DiscoveredWriter> WriterDirectory::writers() const { return listener_->writers(); }

namespace {

// DDS partition matching: a common name, either side's name possibly a wildcard pattern; no
// partition at all is the default partition "".
bool partitions_match(const std::vector<std::string>& a, const std::vector<std::string>& b) {
  const std::vector<std::string> kDefault{""};
  for (const std::string& x : a.empty() ? kDefault : a)
    for (const std::string& y : b.empty() ? kDefault : b)
      if (x == y || ::fnmatch(x.c_str(), y.c_str(), 0) == 0 || ::fnmatch(y.c_str(), x.c_str(), 0) == 0)
        return true;
  return false;
}

std::string last_component(const std::string& topic) {
  const auto slash = topic.rfind('/');
  return slash == std::string::npos ? topic : topic.substr(slash + 1);
}

// A ROS 2 name, as rsg_gateway --ros2 and rmw write them: rt/<ns>/<name>, type <pkg>::msg::dds_::<T>_.
bool is_ros2(const std::string& topic, const std::string& type) {
  return topic.starts_with("rt/") && type.find("::msg::dds_::") != std::string::npos;
}

// How to read a writer whose naming (ROS 2 or rsg's own) differs from the reader's.
std::string naming_hint(const DiscoveredWriter& writer) {
  if (!is_ros2(writer.topic, writer.type)) return "rsg's own names, as rsg_gateway writes without --ros2";
  const std::string path = writer.topic.substr(3);  // without "rt/"
  const auto slash = path.rfind('/');
  std::string hint = "ROS 2 names, as rsg_gateway --ros2 writes: rsg_echo --ros2";
  if (slash != std::string::npos) hint += " --ros2-namespace /" + path.substr(0, slash);
  return hint + " reads it";
}

std::string partition_flags(const std::vector<std::string>& partitions) {
  if (partitions.empty()) return "no --partition";
  std::string flags;
  for (const std::string& partition : partitions)
    flags += (flags.empty() ? "" : " ") + ("--partition " + partition);
  return flags;
}

}  // namespace

std::string describe_partitions(const std::vector<std::string>& partitions) {
  if (partitions.empty()) return "the default partition";
  std::string text = partitions.size() == 1 ? "partition " : "partitions ";
  for (std::size_t i = 0; i < partitions.size(); ++i) text += (i ? ", '" : "'") + partitions[i] + "'";
  return text;
}

std::vector<std::string> explain_no_writer(const WantedWriter& wanted,
                                           const std::vector<DiscoveredWriter>& seen) {
  const std::string domain = std::to_string(wanted.domain);
  std::vector<std::string> lines{"no writer matched: this reader looks for topic '" + wanted.topic +
                                 "', type '" + wanted.type + "', in " +
                                 describe_partitions(wanted.partitions) + " on domain " + domain};
  if (seen.empty()) {
    lines.push_back("no writer of any topic is visible on domain " + domain +
                    ": is the gateway running, on this --domain, and can discovery reach it (multicast, "
                    "--peer, --discovery-server, a security profile)?");
    return lines;
  }
  std::vector<DiscoveredWriter> said;
  std::vector<std::string> other_topics;
  for (const DiscoveredWriter& writer : seen) {
    // One line per topic, type and partitions, however many participants write them.
    const auto same_stream = [&writer](const DiscoveredWriter& other) {
      return other.topic == writer.topic && other.type == writer.type &&
             other.partitions == writer.partitions;
    };
    if (std::any_of(said.begin(), said.end(), same_stream)) continue;
    const bool same_topic = writer.topic == wanted.topic;
    const bool related = same_topic || writer.type == wanted.type ||
                         last_component(writer.topic) == last_component(wanted.topic);
    if (!related) {
      if (std::find(other_topics.begin(), other_topics.end(), writer.topic) == other_topics.end())
        other_topics.push_back(writer.topic);
      continue;
    }
    said.push_back(writer);
    std::string line = "a writer of '" + writer.topic + "' (type '" + writer.type + "') exists in " +
                       describe_partitions(writer.partitions);
    const bool same_partition = partitions_match(writer.partitions, wanted.partitions);
    if (!same_topic && is_ros2(writer.topic, writer.type) != is_ros2(wanted.topic, wanted.type))
      line += ": " + naming_hint(writer) +
              (same_partition ? "" : " (" + partition_flags(writer.partitions) + ")");
    else if (!same_topic)
      line += ": another topic name (--topic " + writer.topic +
              (same_partition ? "" : ", " + partition_flags(writer.partitions)) + ")";
    else if (!same_partition)
      line += ": another partition (" + partition_flags(writer.partitions) + ")";
    else if (writer.type != wanted.type)
      line += ": same topic and partition but another type, so they never match";
    else
      line += ": same topic, type and partition, yet not matched: their QoS or security settings differ";
    lines.push_back(std::move(line));
  }
  if (!other_topics.empty()) {
    std::string line = std::to_string(other_topics.size()) + " other topic" +
                       (other_topics.size() == 1 ? "" : "s") + " visible on domain " + domain + ":";
    for (std::size_t i = 0; i < other_topics.size() && i < 8; ++i)
      line += (i ? ", '" : " '") + other_topics[i] + "'";
    if (other_topics.size() > 8) line += ", ...";
    lines.push_back(std::move(line));
  }
  return lines;
}

std::vector<std::string> explain_mixed_writers(const WantedWriter& wanted,
                                               const std::vector<DiscoveredWriter>& seen) {
  // The participants writing the topic, per partition list the reader matches.
  std::map<std::vector<std::string>, std::vector<std::string>> participants;
  for (const DiscoveredWriter& writer : seen) {
    if (writer.topic != wanted.topic || !partitions_match(writer.partitions, wanted.partitions)) continue;
    auto& list = participants[writer.partitions];
    if (std::find(list.begin(), list.end(), writer.participant) == list.end())
      list.push_back(writer.participant);
  }
  std::vector<std::string> lines;
  for (const auto& [partitions, list] : participants)
    if (list.size() > 1)
      lines.push_back(std::to_string(list.size()) + " programs write '" + wanted.topic + "' in " +
                      describe_partitions(partitions) +
                      ": more than one robot's gateway (or a replay) in one partition, so this reader gets "
                      "their samples interleaved; give each robot its own partition (rsg-gateway@NAME "
                      "takes NAME unless its file sets one)");
  return lines;
}

std::size_t count_other_writers(const std::string& topic, const std::vector<std::string>& partitions,
                                const std::string& own_participant,
                                const std::vector<DiscoveredWriter>& seen) {
  return static_cast<std::size_t>(
      std::count_if(seen.begin(), seen.end(), [&](const DiscoveredWriter& writer) {
        return writer.topic == topic && writer.participant != own_participant &&
               partitions_match(writer.partitions, partitions);
      }));
}

std::string participant_key(const fdds::DomainParticipant& participant) {
  std::ostringstream key;
  key << participant.guid().guidPrefix;
  return key.str();
}

}  // namespace rsg::dds
