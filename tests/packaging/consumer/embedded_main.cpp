// A controller outside rsg, built against the installed package: starts rsg::gateway::EmbeddedGateway on
// a port the kernel picks, sends it one frame and exits 0 when the callback saw that frame (read
// through rsg::eigen's views: the package's two components).
//
//   embedded_consumer PROFILES_DIR DOMAIN
#include <array>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <string>
#include <thread>

#include "rsg/gateway/embedded_gateway.hpp"
#include "rsg/wire/eigen.hpp"
#include "rsg/wire/state_values.hpp"

int main(int argc, char** argv) {
  if (argc != 3) return std::puts("usage: embedded_consumer PROFILES_DIR DOMAIN"), 2;
  std::atomic<int> seen{0};
  std::atomic<double> q0{0};
  rsg::gateway::EmbeddedGateway gateway("listen: 127.0.0.1:0\nlog-level: warn\nprofiles: " +
                                            std::string(argv[1]) + "\ndomain: " + argv[2] + "\n",
                                        [&](const rsg::RobotState& state) {
                                          q0 = rsg::wire::eigen::joints(state.q())(0);
                                          ++seen;
                                        });

  rsg::wire::StateValues values;
  values.selection = rsg::wire::Selection::all();
  for (double& q : values.doubles(rsg::wire::Field::q)) q = 0.5;
  std::array<std::uint8_t, rsg::wire::kMaxFrameBytes> frame{};
  const auto encoded =
      rsg::wire::encode(0, values.selection, values.storage(), rsg::wire::StateValues::layout(), frame);
  const rsg::transport::Endpoint to = gateway.local_endpoint();
  rsg::transport::UdpSocket robot = rsg::transport::UdpSocket::for_sending_to(to);
  if (!encoded || !robot.send_to(std::span(frame.data(), encoded.size), to))
    return std::puts("send failed"), 1;
  for (int i = 0; i < 200 && seen == 0; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  gateway.stop();
  if (seen != 1 || q0 != 0.5)
    return std::printf("embedded: %d samples, q[0]=%g\n", seen.load(), q0.load()), 1;
  std::puts("embedded_consumer: the callback got the frame");
  return 0;
}
