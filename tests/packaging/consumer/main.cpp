// A program outside rsg, built against the installed package: one public header of each client
// layer. Encodes a frame (wire), maps it onto the DDS sample and back (dds), and parses an address
// (transport). Exits 0 when the frame survives the round trip byte for byte.
#include <array>
#include <cstdint>
#include <cstdio>
#include <cstring>

#include "rsg/dds/robot_state.hpp"
#include "rsg/transport/udp_socket.hpp"
#include "rsg/wire/frame.hpp"
#include "rsg/wire/state_values.hpp"

int main() {
  rsg::wire::StateValues values;
  values.packet_number = 5;
  values.selection = rsg::wire::Selection::all();
  for (double& q : values.doubles(rsg::wire::Field::q)) q = 0.25;

  std::array<std::uint8_t, rsg::wire::kMaxFrameBytes> frame{};
  const auto encoded = rsg::wire::encode(values.packet_number, values.selection, values.storage(),
                                         rsg::wire::StateValues::layout(), frame);
  if (!encoded) return std::puts("encode failed"), 1;

  const auto decoded = rsg::wire::decode(std::span(frame.data(), encoded.size));
  if (!decoded) return std::puts("decode failed"), 1;
  rsg::RobotState sample;
  rsg::dds::to_sample(decoded.frame(), sample);

  std::array<std::uint8_t, rsg::wire::kMaxFrameBytes> again{};
  const auto reencoded = rsg::dds::to_frame(sample, again);
  if (!reencoded || reencoded.size != encoded.size ||
      std::memcmp(frame.data(), again.data(), encoded.size) != 0)
    return std::puts("round trip differs"), 1;

  const auto endpoint = rsg::transport::Endpoint::parse("127.0.0.1:1337");
  std::printf("consumer: %zu-byte frame round trip exact, q[0]=%g, endpoint %s\n", encoded.size,
              sample.q()[0], endpoint.to_string().c_str());
  return 0;
}
