// A ROS 2 node with the gateway inside: one process holds rsg::gateway::EmbeddedGateway and an
// rcl node on the one Fast DDS its ROS 2 installation links (ROS 2 Jazzy: Fast DDS 2.14), and the
// node publishes every state the gateway's callback receives as rsg_msgs/msg/RobotState.
//
//   RSG_ROS_DISTRO=jazzy . ros2/env.sh     # or source your ROS 2 Jazzy installation
//   rsg_ros2_node gateway.yaml [TOPIC]     # TOPIC: controller/robot_state by default
//   rsg_sim --to 127.0.0.1:5000 --rate 1000
//
// gateway.yaml is rsg_gateway's configuration file (`listen:` at least). rcl's C API is used because
// the ROS 2 wheels carry no rclcpp; with rclcpp the node part shrinks, the pattern stays.
//
// The pattern: the callback runs on the gateway's ingress thread and must never wait, so it only
// copies the state into a ring the node's own thread drains (no lock, no allocation; a full ring
// drops the state and counts it). The node thread publishes each state as ROS 2 serialized
// bytes: rsg's RobotState sample and rsg_msgs/msg/RobotState have the same CDR (the field table
// generates both), so no field is converted by hand.
#include <RobotStatePubSubTypes.h>
#include <pthread.h>
#include <rcl/error_handling.h>
#include <rcl/rcl.h>
#include <rmw/serialized_message.h>
#include <rosidl_runtime_c/message_type_support_struct.h>
#include <rsg_msgs/msg/robot_state.h>

#include <array>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <memory>
#include <semaphore>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>

#include "rsg/gateway/embedded_gateway.hpp"

namespace {

/// rcl's calls return a code; a failed one ends the program with rcl's message.
void check(rcl_ret_t ret, const char* what) {
  if (ret == RCL_RET_OK) return;
  std::string message = std::string(what) + ": " + rcl_get_error_string().str;
  rcl_reset_error();
  throw std::runtime_error(message);
}

/// The rcl context, node and publisher, released in reverse order (rcl has no RAII of its own in C).
class RclPublisher {
 public:
  RclPublisher(const char* node_name, const char* topic, std::size_t depth) {
    rcl_init_options_t options = rcl_get_zero_initialized_init_options();
    check(rcl_init_options_init(&options, rcl_get_default_allocator()), "rcl_init_options_init");
    const rcl_ret_t init = rcl_init(0, nullptr, &options, &context_);
    check(rcl_init_options_fini(&options), "rcl_init_options_fini");
    check(init, "rcl_init");
    rcl_node_options_t node_options = rcl_node_get_default_options();
    if (rcl_node_init(&node_, node_name, "", &context_, &node_options) != RCL_RET_OK) {
      release();
      check(RCL_RET_ERROR, "rcl_node_init");
    }
    rcl_publisher_options_t publisher_options = rcl_publisher_get_default_options();
    publisher_options.qos.depth =
        depth;  // reliable, keep last: room for a burst the reader acknowledges late
    if (rcl_publisher_init(&publisher_, &node_, ROSIDL_GET_MSG_TYPE_SUPPORT(rsg_msgs, msg, RobotState), topic,
                           &publisher_options) != RCL_RET_OK) {
      release();
      check(RCL_RET_ERROR, "rcl_publisher_init");
    }
  }
  ~RclPublisher() { release(); }
  RclPublisher(const RclPublisher&) = delete;
  RclPublisher& operator=(const RclPublisher&) = delete;

  void publish(const rcl_serialized_message_t& message) {
    check(rcl_publish_serialized_message(&publisher_, &message, nullptr), "rcl_publish_serialized_message");
  }
  /// Readers matched, so that a test can wait for its subscriber before frames flow.
  std::size_t subscriptions() const {
    std::size_t count = 0;
    return rcl_publisher_get_subscription_count(&publisher_, &count) == RCL_RET_OK ? count : 0;
  }

 private:
  // What is released is gone either way: a failed fini has nothing left to report to.
  void release() noexcept {
    if (rcl_publisher_is_valid_except_context(&publisher_)) released(rcl_publisher_fini(&publisher_, &node_));
    if (rcl_node_is_valid_except_context(&node_)) released(rcl_node_fini(&node_));
    if (rcl_context_is_valid(&context_)) released(rcl_shutdown(&context_));
    released(rcl_context_fini(&context_));
  }
  static void released(rcl_ret_t) noexcept { rcl_reset_error(); }

  rcl_context_t context_ = rcl_get_zero_initialized_context();
  rcl_node_t node_ = rcl_get_zero_initialized_node();
  rcl_publisher_t publisher_ = rcl_get_zero_initialized_publisher();
};

/// One producer (the ingress thread), one consumer (the node's thread): each index is written by
/// one side only, and the semaphore counts the states waiting, so neither side ever takes a lock.
class StateRing {
 public:
  static constexpr std::size_t kSlots = 256;

  /// The producer: false when the consumer is kSlots behind (the state is dropped).
  bool push(const rsg::RobotState& state) {
    const std::uint64_t head = head_.load(std::memory_order_relaxed);
    if (head - tail_.load(std::memory_order_acquire) == kSlots) return false;
    slots_[head % kSlots] = state;  // plain data: a copy, no allocation
    head_.store(head + 1, std::memory_order_release);
    waiting_.release();
    return true;
  }
  /// The consumer: the oldest state, once one arrives within `timeout`, else nullptr; pop() it
  /// when done with it.
  const rsg::RobotState* next(std::chrono::milliseconds timeout) {
    if (!waiting_.try_acquire_for(timeout)) return nullptr;
    return &slots_[tail_.load(std::memory_order_relaxed) % kSlots];
  }
  void pop() { tail_.store(tail_.load(std::memory_order_relaxed) + 1, std::memory_order_release); }
  bool empty() const {
    return tail_.load(std::memory_order_acquire) == head_.load(std::memory_order_acquire);
  }

 private:
  std::array<rsg::RobotState, kSlots> slots_{};
  std::atomic<std::uint64_t> head_{0};
  std::atomic<std::uint64_t> tail_{0};
  std::counting_semaphore<> waiting_{0};
};

std::atomic<bool> stop{false};
void request_stop(int) { stop = true; }

std::string read_file(const char* path) {
  std::ifstream in(path);
  std::ostringstream text;
  text << in.rdbuf();
  if (!in) throw std::runtime_error(std::string(path) + ": cannot read");
  return text.str();
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || argc > 3) {
    std::fprintf(stderr, "usage: %s GATEWAY.yaml [TOPIC]\n", argv[0]);
    return 2;
  }
  const char* topic = argc > 2 ? argv[2] : "controller/robot_state";
  std::signal(SIGINT, request_stop);
  std::signal(SIGTERM, request_stop);
  try {
    RclPublisher node("rsg_embedded", topic, 1000);
    auto ring = std::make_unique<StateRing>();
    std::atomic<std::uint64_t> dropped{0};

    // The node's thread: serializes each state into one buffer allocated here, once.
    rsg::RobotStatePubSubType type;
    eprosima::fastrtps::rtps::SerializedPayload_t payload(type.m_typeSize);
    rcl_serialized_message_t message = rmw_get_zero_initialized_serialized_message();
    rcutils_allocator_t allocator = rcutils_get_default_allocator();
    check(rmw_serialized_message_init(&message, type.m_typeSize, &allocator), "rmw_serialized_message_init");
    std::uint64_t published = 0;
    std::jthread publisher([&](std::stop_token stopping) {
      pthread_setname_np(pthread_self(), "rsg-ros2-node");
      while (!stopping.stop_requested() || !ring->empty()) {
        const rsg::RobotState* state = ring->next(std::chrono::milliseconds(100));
        if (state == nullptr) continue;
        const bool serialized = type.serialize(const_cast<rsg::RobotState*>(state), &payload);
        ring->pop();
        if (!serialized) continue;  // cannot happen for a state the gateway decoded
        std::memcpy(message.buffer, payload.data, payload.length);
        message.buffer_length = payload.length;
        try {
          node.publish(message);
        } catch (const std::exception& error) {
          std::fprintf(stderr, "rsg_ros2_node: %s\n", error.what());
          stop = true;
          return;
        }
        ++published;
      }
    });

    {
      rsg::gateway::EmbeddedGateway gateway(read_file(argv[1]), [&](const rsg::RobotState& state) {
        if (!ring->push(state)) dropped.fetch_add(1, std::memory_order_relaxed);
      });
      std::printf("rsg_ros2_node: frames on UDP %s -> ROS 2 topic %s\n",
                  gateway.local_endpoint().to_string().c_str(), topic);
      std::fflush(stdout);
      std::size_t matched = 0;
      while (!stop) {
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
        if (const std::size_t now = node.subscriptions(); now != matched) {
          matched = now;
          std::printf("rsg_ros2_node: %zu subscription(s) matched\n", matched);
          std::fflush(stdout);
        }
      }
      gateway.stop();  // no callback runs after this
    }
    publisher.request_stop();  // after what the ring holds is published
    publisher.join();
    if (rmw_serialized_message_fini(&message) != RMW_RET_OK) rcl_reset_error();
    std::printf("rsg_ros2_node: %llu states published, %llu dropped (ring full)\n",
                static_cast<unsigned long long>(published), static_cast<unsigned long long>(dropped.load()));
    return 0;
  } catch (const std::exception& error) {
    std::fprintf(stderr, "rsg_ros2_node: %s\n", error.what());
    return 1;
  }
}
