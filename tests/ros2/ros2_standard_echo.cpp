// A Cyclone DDS subscriber of the standard ROS 2 messages the gateway publishes, built by idlc from
// idl/ros2/StandardMessages.idl: what a ROS 2 node on rmw_cyclonedds sees of joint_states, /tf and
// external_wrench, minus ROS itself.
//
//   rsg_ros2_standard_echo DOMAIN TOPIC joint_states|tf|wrench MIN_COUNT TIMEOUT_S IDLE_S [sensor_data]
//
// Prints each message as one JSON object (doubles with 17 digits, so they read back exactly).
// Reliable, keep all: every message the writer sends is counted; with `sensor_data`, rclcpp's
// preset of that name (best effort, keep last 5). Stops IDLE_S seconds after the
// last message (or after TIMEOUT_S without any); exit 0 when at least MIN_COUNT arrived.
#include <StandardMessages.h>

#include <cstdio>
#include <iostream>
#include <string>

#include "tests/ros2/ros2_reader.hpp"

namespace {

using rsg::interop::Qos;

std::string number(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.17g", value);
  return text;
}

std::string quoted(const char* text) { return std::string("\"") + (text ? text : "") + "\""; }

std::string doubles(const dds_sequence_double& sequence) {
  std::string out = "[";
  for (uint32_t i = 0; i < sequence._length; ++i) out += (i ? "," : "") + number(sequence._buffer[i]);
  return out + "]";
}

std::string vector3(const geometry_msgs_msg_dds__Vector3_& v) {
  return "[" + number(v.x) + "," + number(v.y) + "," + number(v.z) + "]";
}

std::string header(const std_msgs_msg_dds__Header_& header) {
  return "\"sec\":" + std::to_string(header.stamp.sec) +
         ",\"nanosec\":" + std::to_string(header.stamp.nanosec) + ",\"frame_id\":" + quoted(header.frame_id);
}

std::string joint_state_json(const sensor_msgs_msg_dds__JointState_& message) {
  std::string names = "[";
  for (uint32_t i = 0; i < message.name._length; ++i)
    names += (i ? "," : "") + quoted(message.name._buffer[i]);
  return "{" + header(message.header) + ",\"name\":" + names + "],\"position\":" + doubles(message.position) +
         ",\"velocity\":" + doubles(message.velocity) + ",\"effort\":" + doubles(message.effort) + "}";
}

std::string tf_json(const tf2_msgs_msg_dds__TFMessage_& message) {
  std::string out = "{\"transforms\":[";
  for (uint32_t i = 0; i < message.transforms._length; ++i) {
    const geometry_msgs_msg_dds__TransformStamped_& t = message.transforms._buffer[i];
    const geometry_msgs_msg_dds__Quaternion_& r = t.transform.rotation;
    out += std::string(i ? "," : "") + "{" + header(t.header) +
           ",\"child_frame_id\":" + quoted(t.child_frame_id) +
           ",\"translation\":" + vector3(t.transform.translation) + ",\"rotation\":[" + number(r.x) + "," +
           number(r.y) + "," + number(r.z) + "," + number(r.w) + "]}";
  }
  return out + "]}";
}

std::string wrench_json(const geometry_msgs_msg_dds__WrenchStamped_& message) {
  return "{" + header(message.header) + ",\"force\":" + vector3(message.wrench.force) +
         ",\"torque\":" + vector3(message.wrench.torque) + "}";
}

template <class Message, class ToLine>
unsigned long print_until_idle(dds_entity_t reader, dds_entity_t waitset, dds_duration_t timeout,
                               dds_duration_t idle, ToLine to_line) {
  unsigned long received = 0;
  while (dds_waitset_wait(waitset, nullptr, 0, received ? idle : timeout) > 0) {
    while (true) {
      void* samples[64] = {};  // null: Cyclone loans its own buffers
      dds_sample_info_t infos[64];
      const dds_return_t taken = dds_take(reader, samples, infos, 64, 64);
      if (taken <= 0) break;
      for (dds_return_t i = 0; i < taken; ++i) {
        if (!infos[i].valid_data) continue;
        const std::string line = to_line(*static_cast<const Message*>(samples[i])) + "\n";
        std::fwrite(line.data(), 1, line.size(), stdout);
        ++received;
      }
      dds_return_loan(reader, samples, taken);
    }
    std::fflush(stdout);
  }
  return received;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 7 && !(argc == 8 && std::string(argv[7]) == "sensor_data")) {
    std::cerr
        << "usage: rsg_ros2_standard_echo DOMAIN TOPIC joint_states|tf|wrench MIN_COUNT TIMEOUT_S IDLE_S\n";
    return 2;
  }
  const auto domain = static_cast<dds_domainid_t>(std::stoul(argv[1]));
  const std::string topic_name = argv[2];
  const std::string kind = argv[3];
  const unsigned long min_count = std::stoul(argv[4]);
  const dds_duration_t timeout = DDS_SECS(std::stol(argv[5]));
  const dds_duration_t idle = DDS_SECS(std::stol(argv[6]));
  const dds_topic_descriptor_t* type = kind == "joint_states" ? &sensor_msgs_msg_dds__JointState__desc
                                       : kind == "tf"         ? &tf2_msgs_msg_dds__TFMessage__desc
                                       : kind == "wrench"     ? &geometry_msgs_msg_dds__WrenchStamped__desc
                                                              : nullptr;
  if (!type) {
    std::cerr << "rsg_ros2_standard_echo: unknown kind " << kind << '\n';
    return 2;
  }
  try {
    Qos reader_qos;
    if (argc == 8) {
      dds_qset_reliability(reader_qos.get(), DDS_RELIABILITY_BEST_EFFORT, 0);
      dds_qset_history(reader_qos.get(), DDS_HISTORY_KEEP_LAST, 5);
    } else {
      dds_qset_reliability(reader_qos.get(), DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
      dds_qset_history(reader_qos.get(), DDS_HISTORY_KEEP_ALL, 0);
    }
    rsg::ros2_test::VolatileReader subscription(domain, type, topic_name, reader_qos);
    if (!subscription.wait_for_writer(timeout, "rsg_ros2_standard_echo")) return 1;
    const dds_entity_t reader = subscription.reader(), waitset = subscription.waitset();

    const unsigned long received =
        kind == "joint_states" ? print_until_idle<sensor_msgs_msg_dds__JointState_>(reader, waitset, timeout,
                                                                                    idle, joint_state_json)
        : kind == "tf"
            ? print_until_idle<tf2_msgs_msg_dds__TFMessage_>(reader, waitset, timeout, idle, tf_json)
            : print_until_idle<geometry_msgs_msg_dds__WrenchStamped_>(reader, waitset, timeout, idle,
                                                                      wrench_json);
    std::cerr << "received " << received << std::endl;
    return received >= min_count ? 0 : 1;
  } catch (const std::exception& error) {
    std::cerr << "rsg_ros2_standard_echo: " << error.what() << '\n';
    return 1;
  }
}
