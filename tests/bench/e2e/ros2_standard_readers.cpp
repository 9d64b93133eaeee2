#include "tests/bench/e2e/ros2_standard_readers.hpp"

#include <StandardMessages.h>
#include <StandardMessagesPubSubTypes.h>

#include <atomic>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/subscriber/qos/DataReaderQos.hpp>
#include <stdexcept>
#include <string>

#include "rsg/dds/fastdds.hpp"

namespace rsg::bench {
namespace fdds = eprosima::fastdds::dds;
// CountingReader is a member template, not in an anonymous namespace: the unity build includes this
// file into another, where a member of a type with linkage may not have a type without.
struct Ros2StandardReaders::Readers {
  /// Takes every message of one topic in its listener and counts the valid ones.
  template <class Message, class PubSubType>
  class CountingReader : private fdds::DataReaderListener {
   public:
    CountingReader(dds::Participant& participant, fdds::Subscriber& subscriber, const std::string& topic)
        : subscriber_(subscriber) {
      fdds::DataReaderQos qos = subscriber.get_default_datareader_qos();
      qos.reliability().kind = fdds::RELIABLE_RELIABILITY_QOS;
      qos.durability().kind = fdds::VOLATILE_DURABILITY_QOS;
      qos.history().kind = fdds::KEEP_LAST_HISTORY_QOS;
      qos.history().depth = 100;
      reader_ = subscriber.create_datareader(participant.topic(topic, fdds::TypeSupport(new PubSubType())),
                                             qos, this);
      if (!reader_) throw std::runtime_error("cannot create the reader of " + topic);
    }
    ~CountingReader() override { subscriber_.delete_datareader(reader_); }
    CountingReader(const CountingReader&) = delete;
    CountingReader& operator=(const CountingReader&) = delete;

    std::uint64_t count() const { return count_.load(); }

   private:
    void on_data_available(fdds::DataReader* reader) override {
      fdds::SampleInfo info;
      while (reader->take_next_sample(&message_, &info) == rsg::dds::kOk)
        if (info.valid_data) count_.fetch_add(1);
    }

    fdds::Subscriber& subscriber_;
    fdds::DataReader* reader_ = nullptr;
    Message message_;  // the listener's, reused
    std::atomic<std::uint64_t> count_{0};
  };

  explicit Readers(dds::Participant& participant)
      : subscriber(*participant.subscriber()),
        joint_states(participant, subscriber, "joint_states"),
        tf(participant, subscriber, "tf"),
        wrench(participant, subscriber, "external_wrench") {}

  fdds::Subscriber& subscriber;
  CountingReader<sensor_msgs::msg::dds_::JointState_, sensor_msgs::msg::dds_::JointState_PubSubType>
      joint_states;
  CountingReader<tf2_msgs::msg::dds_::TFMessage_, tf2_msgs::msg::dds_::TFMessage_PubSubType> tf;
  CountingReader<geometry_msgs::msg::dds_::WrenchStamped_, geometry_msgs::msg::dds_::WrenchStamped_PubSubType>
      wrench;
};

Ros2StandardReaders::Ros2StandardReaders(dds::Participant& participant)
    : readers_(std::make_unique<Readers>(participant)) {}

Ros2StandardReaders::~Ros2StandardReaders() = default;

nlohmann::json Ros2StandardReaders::counts() const {
  return {{"joint_states", readers_->joint_states.count()},
          {"tf", readers_->tf.count()},
          {"external_wrench", readers_->wrench.count()}};
}

}  // namespace rsg::bench
