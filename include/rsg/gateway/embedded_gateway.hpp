// The gateway inside a controller's own process: each decoded, validated sample goes straight to
// a callback on the ingress thread, with no socket and no DDS hop in between, while the same
// samples are still published on DDS for everyone else (views, status, recorders unchanged).
//
//   rsg::gateway::EmbeddedGateway gateway(R"(
//     listen: 0.0.0.0:5000
//     domain: 3
//   )", [&](const rsg::RobotState& state) { controller.update(state); });
//   ...                    // frames flow until `gateway` goes out of scope (or stop())
//
// The configuration is rsg_gateway's: the YAML file of `rsg_gateway --config` with the same keys
// as its long flags (`rsg_gateway --help`). `listen` is required; `rt-priority` and `cpu` apply to
// the ingress thread, which this object starts and joins. `log-level` is left to the host
// program: rsg logs through spdlog's default logger, whose level is the host's to set.
//
// The callback runs on the ingress thread for every valid frame, in arrival order, just before
// the sample is written to DDS: whatever it takes delays the publication and the next frame, so
// keep it short and non-blocking (copy what you need, signal your control thread). The sample it
// gets is the one that is published (remote readers receive the same values) and is valid only
// during the call. The path from datagram to callback allocates nothing and takes no lock of
// Fast DDS's: the frame is decoded into a preallocated sample, not a writer loan, so that the
// callback never waits for the writer's mutex (Fast DDS copies the sample when it is written).
#pragma once

#include <functional>
#include <memory>
#include <string_view>

#include "rsg/dds/robot_state.hpp"
#include "rsg/error.hpp"
#include "rsg/transport/udp_socket.hpp"

namespace rsg::gateway {

class EmbeddedGateway {
 public:
  using SampleCallback = std::function<void(const RobotState& sample)>;

  /// Checks `yaml_config`, binds the UDP socket, creates the DDS entities and starts the ingress
  /// thread, which calls `on_sample` from then on. Nothing is left running when it throws.
  /// @throws rsg::InputError when the configuration is unusable (the message names the key or line).
  /// @throws rsg::EnvironmentError when the socket or a DDS entity cannot be created.
  EmbeddedGateway(std::string_view yaml_config, SampleCallback on_sample);
  /// Stops (see stop()).
  ~EmbeddedGateway();
  EmbeddedGateway(EmbeddedGateway&&) noexcept;
  EmbeddedGateway& operator=(EmbeddedGateway&&) noexcept;
  EmbeddedGateway(const EmbeddedGateway&) = delete;
  EmbeddedGateway& operator=(const EmbeddedGateway&) = delete;

  /// Where frames are received (with `listen: HOST:0`, the port the kernel picked).
  /// @throws std::logic_error after stop(): a bug in the caller.
  transport::Endpoint local_endpoint() const;

  /// Ends the ingress thread (within 100 ms), publishes the final status, deletes the DDS
  /// entities and closes the socket. No callback runs once it returns. Idempotent; never from
  /// inside the callback.
  void stop();

 private:
  class Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace rsg::gateway
