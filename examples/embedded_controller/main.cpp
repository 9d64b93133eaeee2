// A controller with the gateway inside: rsg::gateway::EmbeddedGateway hands each validated robot state to
// this process on the ingress thread -- no socket and no DDS hop in between -- while the same
// states are still published on DDS for views, recorders and ROS 2.
//
//   rsg_example_embedded_controller gateway.yaml [SECONDS]
//   rsg_sim --to 127.0.0.1:5000 --rate 1000        # in another shell: a robot
//
// gateway.yaml is rsg_gateway's configuration file (`listen: 0.0.0.0:5000` is the least it needs).
//
// The pattern to copy: the callback only copies the state into a triple buffer (no lock, no
// allocation, never waits), and the control loop on its own thread takes the newest state when
// it needs one. Whatever the callback takes delays the DDS publication and the next frame.
#include <array>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <thread>

#include "rsg/gateway/embedded_gateway.hpp"

namespace {

/// The newest value from one writer thread to one reader thread, wait-free on both sides: the
/// writer fills its own slot and swaps it with the shared middle one; the reader swaps the
/// middle slot in only when it is fresh. Nobody ever touches a slot another thread holds.
template <typename T>
class TripleBuffer {
 public:
  /// The writer's slot: fill it, then publish().
  T& back() { return slots_[back_]; }
  void publish() { back_ = middle_.exchange(back_ | kFresh, std::memory_order_acq_rel) & kIndex; }

  /// The newest published value, or nullptr when nothing was published since the last call.
  const T* take() {
    if ((middle_.load(std::memory_order_relaxed) & kFresh) == 0) return nullptr;
    front_ = middle_.exchange(front_, std::memory_order_acq_rel) & kIndex;
    return &slots_[front_];
  }

 private:
  static constexpr unsigned kFresh = 4, kIndex = 3;
  std::array<T, 3> slots_{};
  unsigned back_ = 0, front_ = 1;
  std::atomic<unsigned> middle_{2};
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
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s GATEWAY.yaml [SECONDS]\n", argv[0]);
    return 2;
  }
  const double seconds = argc > 2 ? std::atof(argv[2]) : 0;  // 0: until Ctrl-C
  std::signal(SIGINT, request_stop);
  std::signal(SIGTERM, request_stop);

  struct Received {
    rsg::RobotState state;
    std::chrono::steady_clock::time_point at;
  };
  TripleBuffer<Received> newest;
  std::atomic<std::uint64_t> frames{0};

  try {
    rsg::gateway::EmbeddedGateway gateway(read_file(argv[1]), [&](const rsg::RobotState& state) {
      Received& slot = newest.back();
      slot.state = state;  // one 2.3 kB copy: plain data, no allocation
      slot.at = std::chrono::steady_clock::now();
      newest.publish();
      frames.fetch_add(1, std::memory_order_relaxed);
    });
    std::printf("embedded controller: frames on UDP %s\n", gateway.local_endpoint().to_string().c_str());

    // The control loop: 1 kHz, the newest state each cycle. A real controller computes its
    // command here; this one reports once a second how fresh its input was.
    const auto start = std::chrono::steady_clock::now();
    auto next = start;
    std::uint64_t cycles = 0, fresh = 0;
    double worst_age_us = 0;
    while (!stop && (seconds <= 0 || next - start < std::chrono::duration<double>(seconds))) {
      next += std::chrono::milliseconds(1);
      std::this_thread::sleep_until(next);
      ++cycles;
      if (const Received* input = newest.take()) {
        ++fresh;
        const double age_us =
            std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - input->at).count();
        worst_age_us = std::max(worst_age_us, age_us);
        if (cycles % 1000 == 0)
          std::printf(
              "frames %llu, fresh in %llu of %llu cycles, q[0] %.4f, robot_mode %u, oldest input %.0f us\n",
              static_cast<unsigned long long>(frames.load()), static_cast<unsigned long long>(fresh),
              static_cast<unsigned long long>(cycles), input->state.q()[0],
              static_cast<unsigned>(input->state.robot_mode()), worst_age_us);
      }
    }
    gateway.stop();
    std::printf("embedded controller: %llu frames\n", static_cast<unsigned long long>(frames.load()));
    return frames.load() > 0 ? 0 : 1;
  } catch (const std::exception& error) {
    std::fprintf(stderr, "embedded controller: %s\n", error.what());
    return 2;
  }
}
