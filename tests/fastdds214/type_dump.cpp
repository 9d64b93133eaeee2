// Prints what of rsg's type support two Fast DDS 2 builds must agree on, one line each: every
// type's name and largest serialized size, the XCDR1 bytes of a sample with every member set, and
// the TypeObject identifiers (minimal and complete equivalence hashes) of the filtered types.
// tests/fastdds214/run.sh runs it from the 2.9 build (fastddsgen 2.3's type support) and the 2.14
// build (tools/fastdds2_typesupport.py) and compares the outputs: the same bytes on the wire, the
// same TypeInformation announced, the same preallocated history.
#include <GatewayStatusPubSubTypes.h>
#include <GatewayStatusTypeObject.h>
#include <RobotStatePubSubTypes.h>
#include <RobotStateTypeObject.h>
#include <StandardMessagesPubSubTypes.h>
#include <fastrtps/types/TypeObjectFactory.h>

#include <array>
#include <cstdio>
#include <string>
#include <type_traits>

#include "dds/internal/fastdds_compat.hpp"
#include "rsg/wire/field_table.hpp"

namespace {

namespace fdds = eprosima::fastdds::dds;

template <class T>
void fill(T& value, double seed) {
  if constexpr (std::is_same_v<T, bool>)
    value = static_cast<int>(seed) % 2 == 1;
  else if constexpr (std::is_arithmetic_v<T>)
    value = static_cast<T>(seed);
  else
    for (std::size_t i = 0; i < value.size(); ++i) fill(value[i], seed + 0.25 * static_cast<double>(i + 1));
}

void dump(fdds::TopicDataType& type, const void* sample) {
  rsg::dds::rtps::SerializedPayload_t payload(rsg::dds::internal::max_serialized_size(type));
  if (!rsg::dds::internal::serialize(type, sample, payload)) {
    std::printf("%s serialize failed\n", type.getName());
    return;
  }
  std::printf("%s max=%u bytes=", type.getName(), rsg::dds::internal::max_serialized_size(type));
  for (std::uint32_t i = 0; i < payload.length; ++i) std::printf("%02x", payload.data[i]);
  std::printf("\n");
}

void identifiers(const char* name) {
  auto* factory = eprosima::fastrtps::types::TypeObjectFactory::get_instance();
  for (const bool complete : {false, true}) {
    const auto* id = factory->get_type_identifier(name, complete);
    std::printf("%s %s=", name, complete ? "complete" : "minimal");
    if (id == nullptr) {
      std::printf("none\n");
      continue;
    }
    for (int i = 0; i < 14; ++i) std::printf("%02x", id->equivalence_hash()[i]);
    std::printf("\n");
  }
}

}  // namespace

int main() {
  rsg::RobotState state;
  double seed = 1;
  state.packet_number(7);
  state.group_select(0x2d);
  fill(state.data_select(), 3);
  fill(state.group_present(), 1);
#define RSG_FILL(name, index, group, mask, type, count, bytes) fill(state.name(), seed += 10);
  RSG_FIELDS(RSG_FILL)
#undef RSG_FILL
  rsg::RobotStatePubSubType robot_state;
  dump(robot_state, &state);

  rsg::GatewayStatus status;
  status.source(std::string("192.0.2.1:40000"));
  status.link_up(true);
  status.rate_hz(999.5);
  status.frames_received(123456789012ULL);
  status.invalid().bad_crc(17);
  status.invalid().bad_value(3);
  status.state_readers(4);
  status.ingress_delay_max_us(250);
  rsg::GatewayStatusPubSubType gateway_status;
  dump(gateway_status, &status);

  sensor_msgs::msg::dds_::JointState_ joints;
  joints.header().stamp().sec(1700000000);
  joints.header().stamp().nanosec(5);
  joints.header().frame_id("base");
  joints.name({"j1", "joint_two", "j3"});
  joints.position({0.5, -1.25, 3});
  joints.velocity({1, 2, 3});
  joints.effort({});
  sensor_msgs::msg::dds_::JointState_PubSubType joint_state;
  dump(joint_state, &joints);

  tf2_msgs::msg::dds_::TFMessage_ tf;
  geometry_msgs::msg::dds_::TransformStamped_ transform;
  transform.header().frame_id("world");
  transform.child_frame_id("ee");
  transform.transform().translation().x(0.1);
  transform.transform().rotation().w(1);
  tf.transforms({transform, transform});
  tf2_msgs::msg::dds_::TFMessage_PubSubType tf_type;
  dump(tf_type, &tf);

  geometry_msgs::msg::dds_::WrenchStamped_ wrench;
  wrench.header().frame_id("ee");
  wrench.wrench().force().z(-9.81);
  wrench.wrench().torque().x(0.5);
  geometry_msgs::msg::dds_::WrenchStamped_PubSubType wrench_type;
  dump(wrench_type, &wrench);

  registerRobotStateTypes();
  registerGatewayStatusTypes();
  identifiers("rsg::RobotState");
  identifiers("rsg::GatewayStatus");
  identifiers("rsg::InvalidFrameCounts");
  return 0;
}
