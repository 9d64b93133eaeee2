// rsg_bench_e2e: end-to-end latency, loss and cost of rsg_gateway, next to baselines measured on
// the same machine with the same frames and the same QoS. tests/bench/run_bench.sh runs it as the
// `e2e` suite; docs/benchmarks/e2e.md explains the method and shows the results.
//
//   rsg_bench_e2e --scenario gateway_udp [--rate 1000] [--duration 30] [--out FILE] [--cdf FILE]
//   rsg_bench_e2e --smoke             a few hundred frames through the gateway: do they arrive?
//   rsg_bench_e2e --role writer ...   (internal) the writer process of the plain Fast DDS baseline
//
// Every run has its own DDS domain (tests/support/test_domain.hpp), ports the kernel picks, and a scratch
// directory for the children's logs (kept, and named, when the run fails).
#include <sys/prctl.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <array>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <iostream>
#include <map>

#include "dds/internal/fastdds_compat.hpp"
#include "rsg/dds/profiles.hpp"
#include "tests/bench/e2e/scenarios.hpp"
#include "tests/support/test_domain.hpp"

namespace {

using json = nlohmann::json;
using rsg::bench::BenchOptions;
using rsg::bench::transport_named;

using Scenario = std::function<json(const BenchOptions&)>;

std::map<std::string, Scenario> scenarios(const std::vector<double>& max_rate_steps,
                                          const std::string& max_rate_transport) {
  using namespace rsg::bench;
  return {
      {"gateway_udp", [](const BenchOptions& o) { return run_gateway(o, transport_named("udp")); }},
      // gateway_udp with JointState, TF and the wrench at 100 Hz each (and their readers).
      {"gateway_udp_ros2_standard", [](const BenchOptions& o) { return run_gateway_ros2_standard(o); }},
      {"gateway_shm", [](const BenchOptions& o) { return run_gateway(o, transport_named("shm")); }},
      {"gateway_datasharing",
       [](const BenchOptions& o) { return run_gateway(o, transport_named("datasharing")); }},
      {"baseline_udp_oneway", [](const BenchOptions& o) { return run_udp_oneway(o); }},
      {"embedded_callback", [](const BenchOptions& o) { return run_embedded(o); }},
      {"floor_relay_cyclone_to_cyclone",
       [](const BenchOptions& o) { return run_floor(o, "relay_cyclone", "cyclone"); }},
      {"floor_relay_cyclone_to_fastdds",
       [](const BenchOptions& o) { return run_floor(o, "relay_cyclone", "fastdds"); }},
      {"floor_relay_fastdds_to_cyclone",
       [](const BenchOptions& o) { return run_floor(o, "relay_fastdds", "cyclone"); }},
      {"floor_relay_fastdds_to_fastdds",
       [](const BenchOptions& o) { return run_floor(o, "relay_fastdds", "fastdds"); }},
      {"floor_gateway_to_cyclone", [](const BenchOptions& o) { return run_floor(o, "gateway", "cyclone"); }},
      {"baseline_fastdds", [](const BenchOptions& o) { return run_fastdds(o, transport_named("udp")); }},
      {"baseline_fastdds_shm", [](const BenchOptions& o) { return run_fastdds(o, transport_named("shm")); }},
      {"baseline_fastdds_datasharing",
       [](const BenchOptions& o) { return run_fastdds(o, transport_named("datasharing")); }},
      {"cyclone_ddsperf", [](const BenchOptions& o) { return run_ddsperf(o); }},
      {"max_rate",
       [=](const BenchOptions& o) {
         return run_max_rate(o, transport_named(max_rate_transport), max_rate_steps);
       }},
      // The RSS soak: a long gateway run over UDP (--duration 300).
      {"soak", [](const BenchOptions& o) { return run_gateway(o, transport_named("udp")); }},
  };
}

/// Logs and profile links of the children; removed at exit unless kept.
class ScratchDir {
 public:
  ScratchDir() {
    std::string name = (std::filesystem::temp_directory_path() / "rsg_bench_XXXXXX").string();
    if (!::mkdtemp(name.data())) throw std::runtime_error("cannot create a scratch directory in /tmp");
    path_ = name;
  }
  ~ScratchDir() {
    std::error_code ignored;
    if (!keep_) std::filesystem::remove_all(path_, ignored);
  }
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;

  const std::filesystem::path& path() const { return path_; }
  void keep() { keep_ = true; }

 private:
  std::filesystem::path path_;
  bool keep_ = false;
};

// rsg_gateway takes one profile file or directory, but needs the project's profiles (its writer
// QoS) and the bench's (transport variants): a directory of links to both serves it and us.
std::filesystem::path link_profiles(const std::filesystem::path& project_profiles,
                                    const std::filesystem::path& bench_profiles,
                                    const std::filesystem::path& scratch) {
  const std::filesystem::path dir = scratch / "profiles";
  std::filesystem::create_directory(dir);
  for (const auto& entry : std::filesystem::directory_iterator(project_profiles))
    if (entry.path().extension() == ".xml")
      std::filesystem::create_symlink(std::filesystem::absolute(entry.path()), dir / entry.path().filename());
  std::filesystem::create_symlink(std::filesystem::absolute(bench_profiles), dir / bench_profiles.filename());
  return dir;
}

// For ctest: every frame sent reaches a subscriber through the gateway over UDP and by data-sharing
// (and data-sharing really is used only when asked for), through each floor relay, and to the
// embedded gateway's callback and its remote DDS reader. Nothing about timing is judged.
//
// `received == sent` for each path, and each key it reads must be there: a report that lost a key
// (a renamed field) fails instead of passing unread.
bool has_key(const json& report, std::string_view name, const char* key) {
  if (report.contains(key)) return true;
  std::cout << "smoke " << name << ": the report has no '" << key << "': " << report.dump() << '\n';
  return false;
}

bool all_arrived(const json& counts, std::string_view name) {
  if (!has_key(counts, name, "sent") || !has_key(counts, name, "received")) return false;
  const auto sent = counts["sent"].get<std::uint64_t>();
  const auto received = counts["received"].get<std::uint64_t>();
  std::cout << "smoke " << name << ": " << received << " of " << sent << " frames arrived\n";
  return sent > 0 && received == sent;
}

int run_smoke(BenchOptions options) {
  constexpr double kSmokeRate = 1000;
  constexpr double kSmokeSeconds = 0.3;
  options.rate_hz = kSmokeRate;
  options.warmup_s = 0;
  options.duration_s = kSmokeSeconds;
  bool ok = true;
  for (const std::string_view transport : {"udp", "datasharing"}) {
    const json run = rsg::bench::run_gateway(options, transport_named(transport));
    const bool arrived = all_arrived(run, transport);
    if (!has_key(run, transport, "data_sharing_used")) {
      ok = false;
      continue;
    }
    const bool used = run["data_sharing_used"].get<bool>();
    std::cout << "smoke " << transport << ": data-sharing " << (used ? "used" : "not used") << '\n';
    ok = ok && arrived && used == (transport == "datasharing");
  }
  // The floor's relays, and the embedded gateway's callback and remote DDS reader.
  const bool relay_cyclone =
      all_arrived(rsg::bench::run_floor(options, "relay_cyclone", "fastdds"), "relay_cyclone -> fastdds");
  const bool relay_fastdds =
      all_arrived(rsg::bench::run_floor(options, "relay_fastdds", "cyclone"), "relay_fastdds -> cyclone");
  const json embedded = rsg::bench::run_embedded(options);
  const bool callback = all_arrived(embedded, "embedded callback");
  const bool reader = has_key(embedded, "embedded", "dds_reader") &&
                      all_arrived(embedded["dds_reader"], "embedded dds_reader");
  return ok && relay_cyclone && relay_fastdds && callback && reader ? 0 : 1;
}

// The 1, 5 and 15 minute load averages: the record of how busy the shared machine was.
json load_average() {
  std::ifstream in("/proc/loadavg");
  std::array<double, 3> averages{};
  for (double& average : averages) in >> average;
  return averages;
}

void write_result(const json& result, const std::string& file_name) {
  if (file_name.empty()) {
    std::cout << result.dump(2) << '\n';
    return;
  }
  std::ofstream file(file_name);
  file << result.dump(2) << '\n';
  if (!file) throw std::runtime_error(file_name + ": cannot write");
}

std::filesystem::path own_directory() {
  return std::filesystem::read_symlink("/proc/self/exe").parent_path();
}

}  // namespace

int main(int argc, char** argv) {
  BenchOptions options;
  options.domain = rsg::test::test_domain();
  options.bin_dir = own_directory();
  options.tools_dir = RSG_TOOLS_DIR;
  options.profiles_dir = rsg::dds::default_profiles_dir();
  std::filesystem::path bench_profiles = RSG_BENCH_PROFILES;
  std::string scenario, role, transport = "udp", out;
  std::vector<double> max_rate_steps = {1000, 2000, 5000, 10000, 20000, 50000, 100000};
  bool smoke = false, keep_scratch = false;

  CLI::App app("rsg_bench_e2e: end-to-end latency of rsg_gateway and its baselines", "rsg_bench_e2e");
  std::vector<std::string> names;
  for (const auto& entry : scenarios({}, {})) names.push_back(entry.first);
  app.add_option("--scenario", scenario, "What to measure")->check(CLI::IsMember(names));
  app.add_option("--bin", options.tools_dir, "Directory of the rsg_gateway measured")->capture_default_str();
  app.add_flag("--smoke", smoke, "Send a few hundred frames through the gateway; fail unless they arrive");
  app.add_option("--rate", options.rate_hz, "Frames per second")->capture_default_str();
  app.add_option("--duration", options.duration_s, "Seconds measured (per step for max_rate)")
      ->capture_default_str();
  app.add_option("--warmup", options.warmup_s, "Seconds sent first and not measured")->capture_default_str();
  app.add_option("--rates", max_rate_steps, "max_rate: the rates tried, in order")->delimiter(',');
  app.add_option("--usage-period", options.usage_period_s, "Seconds between RSS/CPU samples of the gateway")
      ->capture_default_str();
  app.add_option("--out", out, "Write the result JSON here (default: stdout)");
  app.add_option("--cdf", options.cdf_file, "Write the latency CDF here (latency_us fraction)");
  app.add_option("--writer-profile", options.writer_profile, "Writer QoS of the gateway and the DDS baseline")
      ->capture_default_str();
  app.add_option("--reader-profile", options.reader_profile,
                 "Reader QoS instead of the transport's (experiments)");
  app.add_option("--domain", options.domain, "DDS domain")->capture_default_str();
  app.add_flag("--reader-waitset", options.reader_waitset,
               "The Fast DDS reader takes samples on a WaitSet thread, not in its listener (experiments)");
  app.add_option("--gateway-arg", options.gateway_args,
                 "One more rsg_gateway argument (repeatable; experiments)")
      ->allow_extra_args(false);
  app.add_option("--profiles", options.profiles_dir, "The project's XML profiles (file or directory)");
  app.add_option("--bench-profiles", bench_profiles, "The bench's transport profiles")->capture_default_str();
  app.add_option("--ddsperf", options.ddsperf, "Cyclone DDS's ddsperf")->capture_default_str();
  app.add_flag("--keep-scratch", keep_scratch, "Keep the children's logs and stats files");
  app.add_option("--role", role, "(internal) run as the baseline's writer process")
      ->check(CLI::IsMember({"writer", "relay"}));
  app.add_option("--transport", transport, "max_rate and writer role: udp, shm or datasharing")
      ->capture_default_str();
  app.add_option("--topic", options.topic, "(writer role) topic name");
  CLI11_PARSE(app, argc, argv);

  // The sender paces with absolute sleeps on this (the main) thread: without the kernel's default
  // 50 us timer slack a 1 kHz frame leaves within a few us of its due time.
  ::prctl(PR_SET_TIMERSLACK, 1UL);
  // A reader in this process must get its samples over a transport, as one in another process
  // would (embedded_callback reads the embedded gateway's writer from here).
  rsg::dds::internal::disable_intraprocess_delivery();

  if (role == "relay") {
    try {
      rsg::dds::load_profiles(options.profiles_dir);
      rsg::bench::run_relay_role(options);
      return 0;
    } catch (const std::exception& error) {
      std::cerr << "rsg_bench_e2e relay: " << error.what() << '\n';
      return 1;
    }
  }
  if (role == "writer") {
    try {
      rsg::dds::load_profiles(options.profiles_dir);
      const json result = rsg::bench::run_writer_role(options, transport_named(transport));
      if (result["send_failed"].get<std::uint64_t>() != 0)
        throw std::runtime_error("the writer refused samples");
      write_result(result, out);
      return 0;
    } catch (const std::exception& error) {
      std::cerr << "rsg_bench_e2e writer: " << error.what() << '\n';
      return 1;
    }
  }
  if (!smoke && scenario.empty()) {
    std::cerr << "rsg_bench_e2e: give --scenario or --smoke (see --help)\n";
    return 2;
  }

  ScratchDir scratch;
  if (keep_scratch) scratch.keep();
  try {
    options.scratch_dir = scratch.path();
    options.profiles_dir = link_profiles(options.profiles_dir, bench_profiles, scratch.path());
    rsg::dds::load_profiles(options.profiles_dir);
    if (smoke) return run_smoke(options);

    const json load_at_start = load_average();
    json result = scenarios(max_rate_steps, transport).at(scenario)(options);
    result["scenario"] = scenario;
    result["load_average"] = {{"start", load_at_start}, {"end", load_average()}};
    write_result(result, out);
    return 0;
  } catch (const std::exception& error) {
    scratch.keep();
    std::cerr << "rsg_bench_e2e: " << (smoke ? "smoke" : scenario) << ": " << error.what()
              << " (logs kept in " << scratch.path().string() << ")\n";
    return 1;
  }
}
