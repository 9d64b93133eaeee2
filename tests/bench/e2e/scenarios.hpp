// The measurements of rsg_bench_e2e. Each returns its result as a JSON object (times in us) that
// tests/bench/e2e_report.py merges into results.json.
#pragma once

#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

namespace rsg::bench {

/// How samples travel from writer to reader (see bench_profiles.xml).
struct Transport {
  std::string_view name;
  std::string_view participant_profile;
  std::string_view reader_profile;
};
/// udp, shm, datasharing; throws std::invalid_argument for another name.
const Transport& transport_named(std::string_view name);

struct BenchOptions {
  double rate_hz = 1000;
  double duration_s = 30;  ///< measured part of a run
  double warmup_s = 2;     ///< sent first and not measured
  int domain = 0;
  std::string topic = "rsg_bench_state";
  /// The gateway's writer QoS (xml_profiles/gateway.xml); the plain DDS baseline uses it too.
  /// Another profile (bench_profiles.xml has some) is for experiments.
  std::string writer_profile = "rsg_state_writer";
  /// Replaces the transport's reader profile (experiments); empty: the transport's.
  std::string reader_profile;
  /// The bench's Fast DDS reader takes samples on a WaitSet thread instead of in its listener.
  bool reader_waitset = false;
  /// More arguments for rsg_gateway (experiments: --rt-priority 50, --cpu 1).
  std::vector<std::string> gateway_args;

  std::string reader_profile_for(const Transport& transport) const {
    return reader_profile.empty() ? std::string(transport.reader_profile) : reader_profile;
  }
  std::filesystem::path bin_dir;       ///< this binary and the bench's other executables (build/tests/bin)
  std::filesystem::path tools_dir;     ///< rsg_gateway (build/bin: CONTRIBUTING.md, "Build tree")
  std::filesystem::path profiles_dir;  ///< every profile, the gateway's and the bench's (see Scratch)
  std::filesystem::path scratch_dir;   ///< logs and stats files of the children
  std::filesystem::path cdf_file;      ///< where to write the latency CDF; empty: nowhere
  std::filesystem::path ddsperf = "/usr/bin/ddsperf";
  double usage_period_s = 10;  ///< how often the soak samples the gateway's RSS and CPU

  std::uint64_t warmup_frames() const;
  std::uint64_t measured_frames() const;
};

/// Frames sent over UDP to a separate rsg_gateway, received as samples here. Also the gateway's
/// CPU and RSS, after warm-up, at the end and every `usage_period_s` (a long run is the soak test).
nlohmann::json run_gateway(const BenchOptions& options, const Transport& transport);

/// `run_gateway` over UDP with the standard ROS 2 topics on (JointState, TF and the wrench, each at
/// `ros2_standard_hz`) and a reader of each in this process: their cost next to `run_gateway`'s.
nlohmann::json run_gateway_ros2_standard(const BenchOptions& options, double ros2_standard_hz = 100);

/// Gateway runs of `duration_s` each at rising rates until one loses a frame or the sender
/// cannot keep the rate; the highest rate without loss.
nlohmann::json run_max_rate(const BenchOptions& options, const Transport& transport,
                            const std::vector<double>& rates);

/// rsg::gateway::EmbeddedGateway in this process: frames over UDP to it, latency at its callback (the
/// controller's view), and at the same time at a DDS reader of another participant over UDP.
nlohmann::json run_embedded(const BenchOptions& options);

/// The floor: `publisher` (relay_cyclone, relay_fastdds: the leanest relay on each API; gateway:
/// rsg_gateway) as a child process, frames to it over UDP, read here by `reader` (fastdds: the
/// bench's Fast DDS reader; cyclone: rsg_bench_cyclone_reader, a child process).
nlohmann::json run_floor(const BenchOptions& options, std::string_view publisher, std::string_view reader);

/// The relay role of `run_floor` (relay_fastdds): until SIGTERM.
nlohmann::json run_relay_role(const BenchOptions& options);

/// Baseline: the same datagram over UDP loopback, one way.
nlohmann::json run_udp_oneway(const BenchOptions& options);

/// Baseline: the same samples from a plain Fast DDS writer in a child process (this binary in
/// the writer role) to a reader here, with the gateway's writer QoS and no gateway.
nlohmann::json run_fastdds(const BenchOptions& options, const Transport& transport);

/// The writer role of `run_fastdds`: warm-up and measured samples at `rate_hz` once a reader
/// matched; what it sent and its own CPU over the measured samples.
nlohmann::json run_writer_role(const BenchOptions& options, const Transport& transport);

/// Peer reference: Cyclone DDS's ddsperf ping/pong of 2137-byte samples, half the round trip.
nlohmann::json run_ddsperf(const BenchOptions& options);

}  // namespace rsg::bench
