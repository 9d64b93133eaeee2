// One log line whenever the number of writers a tool's reader is matched with changes, e.g.
// "rsg_echo: matched 1 writer of 'robot_state'"; when a matched reader gets no sample for a few
// seconds, where to look; and, when no writer has matched a few seconds after start-up, what the
// reader looks for and what discovery shows instead:
//
//   rsg_echo: warning: no writer matched: this reader looks for topic 'robot_state', type
//             'rsg::RobotState', in partition 'robot1' on domain 0
//   rsg_echo: warning: a writer of 'robot_state' (type 'rsg::RobotState') exists in partition
//             'robot2': another partition (--partition robot2)
//
// and, when writers of more than one program (two robots' gateways) write the topic in one
// partition, that the samples are mixed:
//
//   rsg_echo: warning: 2 programs write 'robot_state' in partition 'robot1': more than one robot's
//             gateway (or a replay) in one partition, so this reader gets their samples interleaved...
//
// Discovery is not symmetric: a gateway may count a reader (and send to it) before that reader
// knows the gateway, and a volatile reader misses what is sent in between. The line is the
// reader's side: an operator learns the tool sees a gateway at all (a wrong domain, partition or
// security setting otherwise looks like silence), and a script or test starts the robot after it.
#pragma once

#include <spdlog/spdlog.h>

#include <chrono>
#include <cstdint>
#include <fastdds/dds/core/status/SubscriptionMatchedStatus.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/ContentFilteredTopic.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <string>
#include <utility>

#include "rsg/dds/writer_directory.hpp"

namespace rsg::app {

class MatchedWriters {
 public:
  /// How long a reader may go without any writer before the tool explains what it sees.
  static constexpr std::chrono::seconds kExplainAfter{3};
  /// How long a matched reader may go without a sample before the tool says where to look.
  static constexpr std::chrono::seconds kSilenceAfter{5};

  explicit MatchedWriters(std::string topic) : topic_(std::move(topic)) {}
  /// Also explains, once, when no writer has matched `kExplainAfter` from now. `directory` is the
  /// one the participant on `domain` was created with; it must outlive this object.
  MatchedWriters(std::string topic, const dds::WriterDirectory& directory, int domain)
      : topic_(std::move(topic)), directory_(&directory), domain_(domain) {}

  /// Cheap enough to call once per wake-up of the tool's loop.
  void update(eprosima::fastdds::dds::DataReader& reader) {
    eprosima::fastdds::dds::SubscriptionMatchedStatus matched;
    reader.get_subscription_matched_status(matched);
    const auto now = std::chrono::steady_clock::now();
    if (matched.current_count != writers_) {
      if (writers_ == 0 && !ever_matched_) matched_at_ = now;
      writers_ = matched.current_count;
      ever_matched_ |= writers_ > 0;
      spdlog::info("matched {} {} of '{}'", writers_, writers_ == 1 ? "writer" : "writers", topic_);
    }
    if (writers_ <= 1) mixed_said_ = false;  // said again should it happen again
    if (directory_ != nullptr && writers_ > 1 && !mixed_said_ && now >= next_mixed_check_) {
      // Discovery's view of the writers may lag the match by a moment: looked at once a second
      // while more than one writer is matched, until it is said.
      next_mixed_check_ = now + std::chrono::seconds(1);
      for (const std::string& line : dds::explain_mixed_writers(wanted(reader), directory_->writers())) {
        spdlog::warn("{}", line);
        mixed_said_ = true;
      }
    }
    if (now - start_ >= kExplainAfter) explain_if_unmatched(reader);
    if (directory_ != nullptr && ever_matched_ && writers_ > 0 && !sampled_ && !silence_said_ &&
        now - matched_at_ >= kSilenceAfter) {
      silence_said_ = true;
      const bool view = dynamic_cast<const eprosima::fastdds::dds::ContentFilteredTopic*>(
                            reader.get_topicdescription()) != nullptr;
      spdlog::warn(
          "matched {} {} of '{}' {} s ago, but no sample has arrived: does the gateway get valid frames? (it "
          "warns 'no datagram on ...' when not; its --stats-file shows link_up and frames_received){}",
          writers_, writers_ == 1 ? "writer" : "writers", topic_, kSilenceAfter.count(),
          view ? "; or no frame carries every group of this view (rsg_echo without --view shows the robot's "
                 "selection, group_select)"
               : "");
    }
  }

  /// Whether any writer has matched since start-up (as of the last update()).
  bool ever_matched() const { return ever_matched_; }

  /// A sample arrived: the reader is not silent.
  void on_sample() { sampled_ = true; }

  /// The explanation now, if no writer has matched yet and it was not given (e.g. before a tool
  /// gives up on its --timeout sooner than kExplainAfter).
  void explain_if_unmatched(eprosima::fastdds::dds::DataReader& reader) {
    if (directory_ == nullptr || explained_ || ever_matched_) return;
    explained_ = true;
    for (const std::string& line : dds::explain_no_writer(wanted(reader), directory_->writers()))
      spdlog::warn("{}", line);
  }

 private:
  // The reader's topic (a view's: the topic it filters), type and partitions.
  dds::WantedWriter wanted(eprosima::fastdds::dds::DataReader& reader) const {
    namespace fdds = eprosima::fastdds::dds;
    const fdds::TopicDescription* description = reader.get_topicdescription();
    std::string topic = description->get_name();
    if (const auto* filtered = dynamic_cast<const fdds::ContentFilteredTopic*>(description))
      topic = filtered->get_related_topic()->get_name();
    return {domain_, topic, description->get_type_name(),
            reader.get_subscriber()->get_qos().partition().names()};
  }

  std::string topic_;
  std::int32_t writers_ = 0;
  const dds::WriterDirectory* directory_ = nullptr;
  int domain_ = 0;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
  std::chrono::steady_clock::time_point matched_at_;
  bool ever_matched_ = false;
  bool explained_ = false;
  bool sampled_ = false;
  bool silence_said_ = false;
  bool mixed_said_ = false;  // more than one robot's writers in a partition: warned
  std::chrono::steady_clock::time_point next_mixed_check_;
};

}  // namespace rsg::app
