// A Cyclone DDS subscriber built from the IDL that ROS's own rosidl made of ros2/rsg_msgs: what a
// ROS 2 node on rmw_cyclonedds would see of the gateway's topics, minus ROS itself.
//
//   rsg_ros2_cyclone_echo DOMAIN TOPIC state|status default|sensor_data COUNT TIMEOUT_S
//   rsg_ros2_cyclone_echo DOMAIN TOPIC publish FILE
//
// `state` prints RobotState samples as rsg's canonical JSON; `status` prints GatewayStatus samples
// as JSON objects of a few members. The QoS is that of rclcpp's preset of that name (default:
// reliable, volatile, keep last 10; sensor_data: best effort, volatile, keep last 5). Exit 0 after
// COUNT samples, 1 on timeout.
//
// `publish` is a ROS 2 publisher of rsg_msgs/RobotState (what a ROS 2 controller node would send
// to the gateway's egress, rt/<ns>/robot_state_cmd): waits for one matched reader, writes the
// canonical JSON lines of FILE (reliable, keep all), exits 0 once the reader acknowledged them.
#include <GatewayStatus_.h>

#include <cstdio>
#include <fstream>
#include <iostream>
#include <string>
#include <thread>

#include "rsg/wire/json.hpp"
#include "tests/interop/cyclone_robot_state.hpp"
#include "tests/ros2/ros2_layout.hpp"  // generated: rsg::ros2_test::ros2_layout()
#include "tests/ros2/ros2_reader.hpp"

namespace {

std::string status_json(const rsg_msgs_msg_dds__GatewayStatus_& status) {
  return std::string("{\"source\":\"") + status.source +
         "\",\"link_up\":" + (status.link_up ? "true" : "false") +
         ",\"frames_received\":" + std::to_string(status.frames_received) +
         ",\"frames_published\":" + std::to_string(status.frames_published) +
         ",\"invalid_bad_crc\":" + std::to_string(status.invalid_bad_crc) +
         ",\"state_readers\":" + std::to_string(status.state_readers) +
         ",\"standard_dropped\":" + std::to_string(status.standard_dropped) + "}";
}

using rsg::interop::Entity;
using rsg::interop::Qos;

int publish(dds_domainid_t domain, const std::string& topic_name, const char* file) {
  std::ifstream input(file);
  if (!input) {
    std::cerr << "rsg_ros2_cyclone_echo: cannot open " << file << '\n';
    return 2;
  }
  const rsg::wire::FieldLayout layout = rsg::ros2_test::ros2_layout();
  Entity participant(dds_create_participant(domain, nullptr, nullptr), "participant");
  Entity topic(dds_create_topic(participant.get(), &rsg_msgs_msg_dds__RobotState__desc, topic_name.c_str(),
                                nullptr, nullptr),
               "topic");
  Qos writer_qos;
  dds_qset_reliability(writer_qos.get(), DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
  dds_qset_history(writer_qos.get(), DDS_HISTORY_KEEP_ALL, 0);
  const dds_data_representation_id_t xcdr1[] = {DDS_DATA_REPRESENTATION_XCDR1};  // what Fast DDS 2.9 reads
  dds_qset_data_representation(writer_qos.get(), 1, xcdr1);
  Entity writer(dds_create_writer(participant.get(), topic.get(), writer_qos.get(), nullptr), "writer");
  dds_publication_matched_status_t matched{};
  for (int waits = 0; waits < 600 && matched.current_count == 0; ++waits) {  // a minute at most
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    dds_get_publication_matched_status(writer.get(), &matched);
  }
  if (matched.current_count == 0) {
    std::cerr << "rsg_ros2_cyclone_echo: no reader on " << topic_name << '\n';
    return 1;
  }
  rsg_msgs_msg_dds__RobotState_ sample;
  std::string line;
  while (std::getline(input, line)) {
    const rsg::wire::Parsed<rsg::wire::StateValues> values = rsg::wire::parse_canonical_json(line);
    if (!values) {
      std::cerr << "rsg_ros2_cyclone_echo: " << values.error() << '\n';
      return 2;
    }
    rsg::interop::to_sample(*values, layout, sample);
    if (const dds_return_t rc = dds_write(writer.get(), &sample); rc != DDS_RETCODE_OK) {
      std::cerr << "rsg_ros2_cyclone_echo: dds_write: " << dds_strretcode(rc) << '\n';
      return 1;
    }
  }
  if (dds_wait_for_acks(writer.get(), DDS_SECS(60)) != DDS_RETCODE_OK) {
    std::cerr << "rsg_ros2_cyclone_echo: the reader did not acknowledge every sample\n";
    return 1;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc == 5 && std::string(argv[3]) == "publish") {
    try {
      return publish(static_cast<dds_domainid_t>(std::stoul(argv[1])), argv[2], argv[4]);
    } catch (const std::exception& error) {
      std::cerr << "rsg_ros2_cyclone_echo: " << error.what() << '\n';
      return 1;
    }
  }
  if (argc != 7) {
    std::cerr
        << "usage: rsg_ros2_cyclone_echo DOMAIN TOPIC state|status default|sensor_data COUNT TIMEOUT_S\n";
    return 2;
  }
  const auto domain = static_cast<dds_domainid_t>(std::stoul(argv[1]));
  const std::string topic_name = argv[2];
  const bool state = std::string(argv[3]) == "state";
  const bool sensor_data = std::string(argv[4]) == "sensor_data";
  const unsigned long count = std::stoul(argv[5]);
  const dds_duration_t timeout = DDS_SECS(std::stol(argv[6]));
  try {
    const rsg::wire::FieldLayout layout = rsg::ros2_test::ros2_layout();
    const dds_topic_descriptor_t* type =
        state ? &rsg_msgs_msg_dds__RobotState__desc : &rsg_msgs_msg_dds__GatewayStatus__desc;
    Qos reader_qos;
    if (sensor_data) {
      dds_qset_reliability(reader_qos.get(), DDS_RELIABILITY_BEST_EFFORT, 0);
      dds_qset_history(reader_qos.get(), DDS_HISTORY_KEEP_LAST, 5);
    } else {
      dds_qset_reliability(reader_qos.get(), DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
      dds_qset_history(reader_qos.get(), DDS_HISTORY_KEEP_LAST, 10);
    }
    rsg::ros2_test::VolatileReader subscription(domain, type, topic_name, reader_qos);
    if (!subscription.wait_for_writer(timeout, "rsg_ros2_cyclone_echo")) return 1;

    rsg::wire::StateValues values;
    const bool complete =
        state ? rsg::interop::print_samples<rsg_msgs_msg_dds__RobotState_>(
                    subscription.reader(), subscription.waitset(), count, timeout, "rsg_ros2_cyclone_echo",
                    [&](const rsg_msgs_msg_dds__RobotState_& sample) {
                      rsg::interop::to_values(sample, layout, values);
                      return rsg::wire::to_canonical_json(values);
                    })
              : rsg::interop::print_samples<rsg_msgs_msg_dds__GatewayStatus_>(
                    subscription.reader(), subscription.waitset(), count, timeout, "rsg_ros2_cyclone_echo",
                    status_json);
    if (!complete) return 1;
    return 0;
  } catch (const std::exception& error) {
    std::cerr << "rsg_ros2_cyclone_echo: " << error.what() << '\n';
    return 1;
  }
}
