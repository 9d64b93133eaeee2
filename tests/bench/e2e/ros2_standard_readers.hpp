// Readers of rsg_gateway's standard ROS 2 topics (--joint-states, --tf, --external-wrench) for the
// e2e bench: they make the gateway send those messages for real (a writer without readers only
// serializes) and count what arrives. Plain DDS names, as the bench's gateway runs without --ros2.
#pragma once

#include <memory>
#include <nlohmann/json.hpp>

#include "rsg/dds/participant.hpp"

namespace rsg::bench {

class Ros2StandardReaders {
 public:
  /// Reliable, volatile readers of joint_states, tf and external_wrench in `participant`.
  /// Throws std::runtime_error.
  explicit Ros2StandardReaders(dds::Participant& participant);
  ~Ros2StandardReaders();
  Ros2StandardReaders(const Ros2StandardReaders&) = delete;
  Ros2StandardReaders& operator=(const Ros2StandardReaders&) = delete;

  /// {"joint_states": N, "tf": N, "external_wrench": N}: messages taken so far.
  nlohmann::json counts() const;

 private:
  struct Readers;
  std::unique_ptr<Readers> readers_;
};

}  // namespace rsg::bench
