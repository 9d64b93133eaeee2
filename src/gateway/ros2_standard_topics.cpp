#include "gateway/ros2_standard_topics.hpp"

#include <StandardMessages.h>
#include <StandardMessagesPubSubTypes.h>
#include <pthread.h>

#include <Eigen/Geometry>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/qos/DataWriterQos.hpp>
#include <stdexcept>

#include "gateway/entities.hpp"
#include "rsg/error.hpp"
#include "rsg/wire/eigen.hpp"

namespace rsg::gateway {
namespace fdds = eprosima::fastdds::dds;
namespace {

namespace ros_time = builtin_interfaces::msg::dds_;
namespace geometry = geometry_msgs::msg::dds_;

// What a default rclcpp subscription (reliable, volatile, keep last 10) and a sensor_data one
// (best effort) both match, with tf2's listener depth (100) so that a reader that is late by up to
// a second at 100 Hz still gets every message.
fdds::DataWriterQos writer_qos(const fdds::Publisher& publisher) {
  fdds::DataWriterQos qos = publisher.get_default_datawriter_qos();
  qos.reliability().kind = fdds::RELIABLE_RELIABILITY_QOS;
  qos.durability().kind = fdds::VOLATILE_DURABILITY_QOS;
  qos.history().kind = fdds::KEEP_LAST_HISTORY_QOS;
  qos.history().depth = 100;
  // Variable-size samples: history slots grow to what is written, not to the type's bound.
  qos.endpoint().history_memory_policy = rsg::dds::rtps::PREALLOCATED_WITH_REALLOC_MEMORY_MODE;
  return qos;
}

// ROS 2 time: seconds and nanoseconds of the same instant.
ros_time::Time_ ros2_time(std::int64_t ns) {
  ros_time::Time_ time;
  std::int64_t sec = ns / 1'000'000'000;
  std::int64_t nanosec = ns % 1'000'000'000;
  if (nanosec < 0) {
    nanosec += 1'000'000'000;
    --sec;
  }
  time.sec(static_cast<std::int32_t>(sec));
  time.nanosec(static_cast<std::uint32_t>(nanosec));
  return time;
}

template <std::size_t N>
void assign(std::vector<double>& out, const std::array<double, N>& values) {
  out.assign(values.begin(), values.end());  // keeps its capacity: no allocation after the first
}

geometry::Vector3_ vector3(double x, double y, double z) {
  geometry::Vector3_ v;
  v.x(x);
  v.y(y);
  v.z(z);
  return v;
}

}  // namespace

struct Ros2StandardTopics::Messages {
  sensor_msgs::msg::dds_::JointState_ joint_state;
  tf2_msgs::msg::dds_::TFMessage_ tf;
  geometry::WrenchStamped_ wrench;
};

Ros2StandardTopics::Ros2StandardTopics(dds::Participant& participant, fdds::Publisher& publisher,
                                       Options options)
    : options_(std::move(options)),
      participant_(participant),
      publisher_(publisher),
      messages_(std::make_unique<Messages>()) {
  // What never changes is set once: names and frames.
  messages_->joint_state.name() = options_.joint_names;
  messages_->tf.transforms().resize(1);
  messages_->tf.transforms()[0].header().frame_id(options_.base_frame);
  messages_->tf.transforms()[0].child_frame_id(options_.ee_frame);
  messages_->wrench.header().frame_id(options_.wrench_frame);
  if (options_.joint_states && options_.joint_names.size() != 7)
    throw InputError("joint_states needs 7 joint names");
  // Should a writer be refused, the ones created so far are deleted by their owners.
  create(joint_states_, options_.joint_states,
         fdds::TypeSupport(new sensor_msgs::msg::dds_::JointState_PubSubType()));
  create(tf_, options_.tf, fdds::TypeSupport(new tf2_msgs::msg::dds_::TFMessage_PubSubType()));
  create(wrench_, options_.external_wrench, fdds::TypeSupport(new geometry::WrenchStamped_PubSubType()));
  thread_ = std::jthread([this] { run(); });
}

Ros2StandardTopics::~Ros2StandardTopics() {
  stop_.store(true, std::memory_order_release);
  wake_.fetch_add(1, std::memory_order_release);
  wake_.notify_one();
  thread_.join();
}  // then the owners delete the writers

void Ros2StandardTopics::create(Writer& writer, const std::optional<Output>& output, fdds::TypeSupport type) {
  if (!output) return;
  fdds::Topic* topic = participant_.topic(output->topic, type);
  writer.writer =
      dds::own(publisher_, create_writer(publisher_, topic, writer_qos(publisher_), options_.data_sharing),
               "the writer of '" + output->topic + "'");
  writer.decimator.emplace(output->decimation);
}

std::uint32_t Ros2StandardTopics::matched_readers() const {
  std::uint32_t readers = 0;
  for (const Writer* output : {&joint_states_, &tf_, &wrench_}) {
    fdds::PublicationMatchedStatus matched;
    if (output->writer && output->writer->get_publication_matched_status(matched) == dds::kOk)
      readers += static_cast<std::uint32_t>(matched.current_count);
  }
  return readers;
}

std::vector<const fdds::DataWriter*> Ros2StandardTopics::writers() const {
  std::vector<const fdds::DataWriter*> on;
  for (const Writer* output : {&joint_states_, &tf_, &wrench_})
    if (output->writer) on.push_back(output->writer.get());
  return on;
}

std::array<std::uint64_t, 3> Ros2StandardTopics::written() const {
  return {joint_states_.written.load(), tf_.written.load(), wrench_.written.load()};
}

void Ros2StandardTopics::offer(const RobotState& sample, const wire::Selection& selection,
                               std::chrono::nanoseconds t) noexcept {
  std::uint8_t outputs = 0;
  // A decimator counts only the frames its output could publish.
  if (joint_states_.decimator && selection.contains(wire::Field::q) && joint_states_.decimator->due(t))
    outputs |= kJointStates;
  if (tf_.decimator && selection.contains(wire::Field::O_T_EE) && tf_.decimator->due(t)) outputs |= kTf;
  if (wrench_.decimator && selection.contains(wire::Field::O_F_ext_hat_K) && wrench_.decimator->due(t))
    outputs |= kWrench;
  if (outputs == 0) return;

  const std::uint64_t head = head_.load(std::memory_order_relaxed);
  if (head - tail_.load(std::memory_order_acquire) == kRingSlots) {
    dropped_.fetch_add(1, std::memory_order_relaxed);
    return;
  }
  Snapshot& slot = ring_[head % kRingSlots];
  slot.stamp_ns = std::chrono::duration_cast<std::chrono::nanoseconds>(
                      std::chrono::system_clock::now().time_since_epoch())
                      .count();
  slot.outputs = outputs;
  if (outputs & kJointStates) {
    slot.q = sample.q();
    slot.has_dq = selection.contains(wire::Field::dq);
    slot.has_tau = selection.contains(wire::Field::tau_J);
    slot.dq = sample.dq();
    slot.tau_J = sample.tau_J();
  }
  if (outputs & kTf) slot.O_T_EE = sample.O_T_EE();
  if (outputs & kWrench) slot.O_F_ext_hat_K = sample.O_F_ext_hat_K();
  head_.store(head + 1, std::memory_order_release);
  wake_.fetch_add(1, std::memory_order_release);
  wake_.notify_one();  // a futex wake only when the thread sleeps
}

void Ros2StandardTopics::run() {
  ::pthread_setname_np(::pthread_self(), "rsg-ros2-topics");  // top -H, perf, tests find it by name
  while (true) {
    const std::uint32_t wake = wake_.load(std::memory_order_acquire);
    const std::uint64_t head = head_.load(std::memory_order_acquire);
    std::uint64_t tail = tail_.load(std::memory_order_relaxed);
    for (; tail != head; ++tail) {
      publish(ring_[tail % kRingSlots]);
      tail_.store(tail + 1, std::memory_order_release);
    }
    if (stop_.load(std::memory_order_acquire) && head_.load(std::memory_order_acquire) == tail) return;
    wake_.wait(wake, std::memory_order_acquire);  // returns at once if anything came since the load
  }
}

void Ros2StandardTopics::publish(const Snapshot& snapshot) {
  // Built here, off the ingress thread, into messages that keep their storage between calls.
  auto& [joint_state, tf_message, wrench] = *messages_;
  const ros_time::Time_ stamp = ros2_time(snapshot.stamp_ns);

  if (snapshot.outputs & kJointStates) {
    joint_state.header().stamp(stamp);
    assign(joint_state.position(), snapshot.q);
    // ROS leaves velocity or effort empty when it is not known.
    if (snapshot.has_dq)
      assign(joint_state.velocity(), snapshot.dq);
    else
      joint_state.velocity().clear();
    if (snapshot.has_tau)
      assign(joint_state.effort(), snapshot.tau_J);
    else
      joint_state.effort().clear();
    if (dds::succeeded(joint_states_.writer->write(&joint_state))) joint_states_.written.fetch_add(1);
  }
  if (snapshot.outputs & kTf) {
    geometry::TransformStamped_& transform = tf_message.transforms()[0];
    transform.header().stamp(stamp);
    const auto pose = wire::eigen::pose(snapshot.O_T_EE);  // column-major, as the frame stores it
    transform.transform().translation(vector3(pose(0, 3), pose(1, 3), pose(2, 3)));
    // A measured rotation is orthonormal to within rounding; normalising keeps the quaternion a
    // unit one (tf2 rejects others) whatever the last bits say.
    const Eigen::Quaterniond rotation =
        Eigen::Quaterniond(Eigen::Matrix3d(pose.topLeftCorner<3, 3>())).normalized();
    geometry::Quaternion_& q = transform.transform().rotation();
    q.x(rotation.x());
    q.y(rotation.y());
    q.z(rotation.z());
    q.w(rotation.w());
    if (dds::succeeded(tf_.writer->write(&tf_message))) tf_.written.fetch_add(1);
  }
  if (snapshot.outputs & kWrench) {
    wrench.header().stamp(stamp);
    const auto& f = snapshot.O_F_ext_hat_K;  // N, N, N, Nm, Nm, Nm
    wrench.wrench().force(vector3(f[0], f[1], f[2]));
    wrench.wrench().torque(vector3(f[3], f[4], f[5]));
    if (dds::succeeded(wrench_.writer->write(&wrench))) wrench_.written.fetch_add(1);
  }
}

}  // namespace rsg::gateway
