// The standard ROS 2 topics the gateway can add to the RobotState stream, each at its own rate:
// sensor_msgs/JointState (q, dq, tau_J), tf2_msgs/TFMessage (base -> end effector from O_T_EE) and
// geometry_msgs/WrenchStamped (O_F_ext_hat_K). What robot_state_publisher, RViz, MoveIt and
// PlotJuggler consume without knowing rsg_msgs. Types: idl/ros2/StandardMessages.idl.
//
// These types hold strings and sequences: they are serialized on write, which must not slow the
// RobotState path. So the ingress thread only decides (Decimator) and copies the few fields a
// due frame needs into a preallocated ring -- no allocation, no lock, no DDS call --, and a
// thread of this class builds the messages and writes them. A full ring drops the snapshot and
// counts it (dropped()), never waits.
#pragma once

#include <array>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "gateway/data_sharing.hpp"
#include "gateway/decimator.hpp"
#include "rsg/dds/owned.hpp"
#include "rsg/dds/participant.hpp"
#include "rsg/dds/robot_state.hpp"

namespace rsg::gateway {

class Ros2StandardTopics {
 public:
  struct Output {
    Decimation decimation;
    std::string topic;  ///< the DDS topic, e.g. rt/robot1/joint_states
  };
  struct Options {
    std::optional<Output> joint_states;
    std::optional<Output> tf;
    std::optional<Output> external_wrench;
    std::vector<std::string> joint_names;                 ///< 7 names, joint 1 first
    std::string base_frame;                               ///< TF parent: the frame O of O_T_EE
    std::string ee_frame;                                 ///< TF child: the end effector
    std::string wrench_frame;                             ///< frame_id of the wrench (O_F_ext_hat_K is in O)
    DataSharing data_sharing = DataSharing::kAsProfiled;  ///< of every writer (entities.hpp)

    bool any() const { return joint_states || tf || external_wrench; }
  };

  /// Creates the writers in `publisher` and starts the publishing thread.
  /// @throws rsg::InputError for a configuration it cannot publish (joint_states without 7 joint
  /// names), rsg::EnvironmentError when DDS refuses a writer.
  Ros2StandardTopics(dds::Participant& participant, eprosima::fastdds::dds::Publisher& publisher,
                     Options options);
  /// Stops the thread (what is queued is still written), then deletes the writers.
  ~Ros2StandardTopics();
  Ros2StandardTopics(const Ros2StandardTopics&) = delete;
  Ros2StandardTopics& operator=(const Ros2StandardTopics&) = delete;

  /// Ingress thread, per valid frame: takes what falls due for each output whose fields the frame
  /// carries. `t` paces the rates (the robot's time, else arrival). Allocates nothing.
  void offer(const RobotState& sample, const wire::Selection& selection, std::chrono::nanoseconds t) noexcept;

  /// Snapshots dropped because the publishing thread was behind by a whole ring.
  std::uint64_t dropped() const { return dropped_.load(std::memory_order_relaxed); }
  /// Readers matched by the writers of all outputs, summed.
  std::uint32_t matched_readers() const;
  /// Messages written so far, per output (joint_states, tf, external_wrench).
  std::array<std::uint64_t, 3> written() const;
  /// The writers of the outputs that are on (joint_states, tf, external_wrench order): their QoS.
  std::vector<const eprosima::fastdds::dds::DataWriter*> writers() const;

  static constexpr std::size_t kRingSlots = 64;

 private:
  enum Bit : std::uint8_t { kJointStates = 1, kTf = 2, kWrench = 4 };

  // What a due frame leaves for the publishing thread: the host's wall clock at reception and the
  // fields the due outputs need.
  struct Snapshot {
    std::int64_t stamp_ns = 0;  // system_clock since its epoch
    std::uint8_t outputs = 0;   // Bit
    bool has_dq = false;
    bool has_tau = false;
    std::array<double, 7> q{};
    std::array<double, 7> dq{};
    std::array<double, 7> tau_J{};
    std::array<double, 16> O_T_EE{};
    std::array<double, 6> O_F_ext_hat_K{};
  };

  struct Writer {
    dds::OwnedWriter writer;  // none when the output is off
    std::optional<Decimator> decimator;
    std::atomic<std::uint64_t> written{0};
  };

  struct Messages;  // the ROS messages, reused from one write to the next (publishing thread only)

  void run();
  void publish(const Snapshot& snapshot);
  void create(Writer& writer, const std::optional<Output>& output, eprosima::fastdds::dds::TypeSupport type);

  Options options_;
  dds::Participant& participant_;
  eprosima::fastdds::dds::Publisher& publisher_;
  Writer joint_states_;
  Writer tf_;
  Writer wrench_;
  std::unique_ptr<Messages> messages_;

  // Single producer (ingress), single consumer (run): slots [tail, head) are full.
  std::array<Snapshot, kRingSlots> ring_{};
  std::atomic<std::uint64_t> head_{0};
  std::atomic<std::uint64_t> tail_{0};
  std::atomic<std::uint32_t> wake_{0};  // bumped on every push and on stop; run() waits on it
  std::atomic<bool> stop_{false};
  std::atomic<std::uint64_t> dropped_{0};
  std::jthread thread_;  // last: starts once everything it uses exists; named rsg-ros2-topics
};

}  // namespace rsg::gateway
