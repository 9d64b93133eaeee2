// rsg_sim: a simulated Franka Panda streaming SEND_BUF frames (docs/protocol.md) over UDP, with the
// faults a gateway must survive. See `rsg_sim --help`; the logic lives in rsg_sim_core.
#include <CLI/CLI.hpp>
#include <atomic>
#include <fstream>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

#include "app/file_options.hpp"
#include "app/number_checks.hpp"
#include "app/stop_on_signal.hpp"
#include "app/tool_main.hpp"
#include "capture/pcap_file.hpp"
#include "rsg/error.hpp"
#include "rsg/transport/host_port.hpp"
#include "tools/sim/replay.hpp"
#include "tools/sim/simulator.hpp"
#include "tools/sim/udp_stream.hpp"

namespace {

using rsg::app::kExitFailure;
using rsg::app::kExitOk;

struct Options {
  std::string to;
  std::optional<std::uint64_t> count;
  std::optional<double> duration_s;
  std::vector<std::string> every;
  std::optional<rsg::wire::Selection> base_selection;  // from --groups and --fields
  unsigned pause_ms = 0;
  std::string report_path;
  std::string record_path;
  std::string pcap_path;
  std::string replay_path;
  rsg::tools::sim::ReplayOptions replay;
};

constexpr const char* kScheduleHelp = R"(
rsg::wire::Selection and schedule:
  Without --groups, --fields or --every, every frame carries all 44 fields (2137 bytes, IP-fragmented
  above a 1500-byte MTU). --groups and --fields select fields for every frame; --every adds a periodic
  entry. Frame k (counted from 0, dropped frames included) carries the union of --groups, --fields and
  every --every N:LIST whose N divides k. LIST is comma-separated field names of docs/protocol.md, group
  tokens g0..g5 and/or "all". Example:
      --every 1:q,dq,time --every 100:g1      q, dq, time always; group 1 too in frames 0, 100, 200...
  A frame that no entry covers is sent with no field (a valid header-only frame).
  A valid selection request received on the sending socket replaces all of this from the next frame.

Time:
  `time` is whole milliseconds of robot time since (re)start, frame k being k/rate seconds in (plus
  pauses). Above 1 kHz consecutive frames share a millisecond, so `time` repeats (non-decreasing
  instead of strictly increasing); the packet number still changes every frame. The motion is
  computed at the exact frame instant, not at the rounded millisecond. A host too busy to send a
  frame within 2 ms of when it is due stalls the stream: it goes on from there, the link silent
  meanwhile, without a burst of the frames due (counted in the report's "stalls"; `time` is not
  moved).

Faults:
  A frame suffers at most one fault. --X-every N hits frames N-1, 2N-1, ... (drop, corrupt, duplicate,
  reorder, in that priority); otherwise one random draw per frame picks a fault by the probabilities
  (which must sum to <= 1). A corrupted frame is replaced by a datagram that a conformant decoder
  rejects with exactly one category; successive corruptions cycle through --corrupt-categories
  (default: all seven). A reordered frame is sent right after the next valid frame; a dropped frame
  still uses its packet number.

Report (--report FILE, and a summary on stderr):
  {"sent","valid","dropped","duplicated","reordered",
   "invalid":{"truncated","length_mismatch","bad_crc","bad_request","reserved_bits",
              "selection_mismatch","bad_value"},
   "restarts","pauses","stalls","selection_requests","invalid_requests","send_failures","longest_gap_us"}
  sent = valid + all invalid (datagrams on the wire, a duplicate counted twice).)";

/// Parses --corrupt-categories' comma-separated list of docs/protocol.md's error categories.
/// @return the categories, or a failure naming the one that is not.
rsg::wire::Parsed<std::vector<rsg::wire::ErrorCategory>> parse_categories(const std::string& list) {
  std::vector<rsg::wire::ErrorCategory> categories;
  std::size_t begin = 0;
  while (begin <= list.size()) {
    const std::size_t comma = std::min(list.find(',', begin), list.size());
    const std::string name = list.substr(begin, comma - begin);
    const auto category = rsg::wire::parse_error_category(name);
    if (!category || *category == rsg::wire::ErrorCategory::kNone)
      return rsg::wire::ParseFailure{"'" + name + "' is not an error category of docs/protocol.md"};
    categories.push_back(*category);
    begin = comma + 1;
  }
  return categories;
}

void add_options(CLI::App& app, Options& options, rsg::tools::sim::SimConfig& config) {
  app.add_option("--to", options.to, "Where to send frames, HOST:PORT")
      ->check([](const std::string& text) {
        return rsg::transport::parse_host_port(text, rsg::transport::HostPortRule::kPortRequired).error();
      })
      ->required();
  app.add_option("--rate", config.rate_hz, "Frames per second")
      ->check(rsg::app::number_in(1e-3, 1e6))
      ->capture_default_str();
  auto* count = app.add_option("--count", options.count, "Send this many frames, then exit");
  app.add_option("--duration", options.duration_s, "Send for this many seconds, then exit")
      ->check(rsg::app::positive_number())
      ->excludes(count);
  app.add_option("--seed", config.seed, "Seed of the motion and of the random faults")->capture_default_str();

  const auto selection_option = [&](const char* name, auto parse, const char* help) {
    app.add_option_function<std::string>(
        name,
        [&options, parse, name](const std::string& list) {
          const rsg::wire::Parsed<rsg::wire::Selection> selection = parse(list);
          if (!selection) throw CLI::ValidationError(name, selection.error());
          options.base_selection = options.base_selection.value_or(rsg::wire::Selection{}) | *selection;
        },
        help);
  };
  selection_option("--groups", rsg::wire::parse_group_list,
                   "Comma-separated group numbers 0..5 for every frame");
  selection_option("--fields", rsg::wire::parse_field_list, "Comma-separated field names for every frame");
  app.add_option("--every", options.every, "N:LIST, repeatable: LIST in frames whose index N divides");

  auto* faults = app.add_option_group("Faults");
  rsg::tools::sim::FaultConfig& fault = config.faults;
  const auto probability = [&](const char* name, double& value, const char* what) {
    faults->add_option(name, value, std::string("Probability that a frame is ") + what)
        ->check(rsg::app::number_in(0.0, 1.0));
  };
  probability("--drop", fault.drop, "not sent");
  probability("--duplicate", fault.duplicate, "sent twice");
  probability("--reorder", fault.reorder, "sent after the next one");
  probability("--corrupt", fault.corrupt, "replaced by an invalid datagram");
  faults->add_option("--drop-every", fault.drop_every, "Drop frames N-1, 2N-1, ...");
  faults->add_option("--duplicate-every", fault.duplicate_every, "Duplicate frames N-1, 2N-1, ...");
  faults->add_option("--reorder-every", fault.reorder_every, "Reorder frames N-1, 2N-1, ...");
  faults->add_option("--corrupt-every", fault.corrupt_every, "Corrupt frames N-1, 2N-1, ...");
  faults->add_option_function<std::string>(
      "--corrupt-categories",
      [&fault](const std::string& list) {
        auto categories = parse_categories(list);
        if (!categories) throw CLI::ValidationError("--corrupt-categories", categories.error());
        fault.corrupt_categories = std::move(categories).value();
      },
      "Comma-separated categories that corruptions cycle through (default: all seven)");
  auto* pause_after =
      faults->add_option("--pause-after", config.pause_after,
                         "After N frames, the link goes silent for --pause-ms (time runs on)");
  faults->add_option("--pause-ms", options.pause_ms, "Length of the --pause-after silence, ms")
      ->needs(pause_after);
  faults->add_option("--restart-after", config.restart_after,
                     "After N frames, the robot reboots: time and packet number restart from 0");

  app.add_option("--report", options.report_path, "Write the JSON report of what was sent to FILE")
      ->check(rsg::app::writable_file());
  app.add_option("--record", options.record_path,
                 "Write the canonical JSON of every valid datagram sent to FILE, one per line")
      ->check(rsg::app::writable_file());
  app.add_option("--pcap", options.pcap_path, "Also write every datagram sent to FILE as a pcap capture")
      ->check(rsg::app::writable_file());

  auto* replay = app.add_option_group("Replay", "Send a capture's frames instead of simulating");
  auto* file =
      replay->add_option("--replay", options.replay_path,
                         "Replay the SEND_BUF datagrams of this pcap/pcapng file at their original timing");
  replay->add_option("--speed", options.replay.speed, "Replay this many times faster")
      ->check(rsg::app::number_in(1e-3, 1e6))
      ->needs(file)
      ->capture_default_str();
  replay->add_flag("--loop", options.replay.loop, "Start the capture over at its end, until stopped")
      ->needs(file);
  replay
      ->add_option("--port", options.replay.port,
                   "Replay the datagrams sent to this UDP port (default: that of the first valid frame)")
      ->needs(file);
  for (const char* simulation_only :
       {"--count", "--duration", "--every", "--groups", "--fields", "--record", "--report", "--pcap"})
    file->excludes(app.get_option(simulation_only));
}

int run_replay(const Options& options) {
  const rsg::transport::Endpoint peer = rsg::transport::Endpoint::parse(options.to);
  rsg::transport::UdpSocket socket = rsg::transport::UdpSocket::for_sending_to(peer);
  std::atomic<bool> stop{false};
  const rsg::app::StopOnSignal signals([&stop] { stop = true; });
  const rsg::tools::sim::ReplayReport report =
      rsg::tools::sim::replay(options.replay_path, socket, peer, options.replay, stop);
  spdlog::info("replayed {} datagrams to port {} ({} complete passes, {} send failures)", report.sent,
               report.port, report.passes, report.send_failures);
  return report.send_failures == 0 ? kExitOk : kExitFailure;
}

/// Turns the selection options into the schedule; throws CLI::ValidationError.
rsg::tools::sim::Schedule build_schedule(const Options& options) {
  rsg::tools::sim::Schedule schedule;
  if (options.base_selection) schedule.add(1, *options.base_selection);
  for (const std::string& spec : options.every) {
    const rsg::wire::Parsed<rsg::tools::sim::Schedule::Entry> entry =
        rsg::tools::sim::parse_schedule_entry(spec);
    if (!entry) throw CLI::ValidationError("--every", entry.error());
    schedule.add(*entry);
  }
  if (schedule.empty()) schedule.add(1, rsg::wire::Selection::all());
  return schedule;
}

void check_probabilities(const rsg::tools::sim::FaultConfig& faults) {
  if (faults.drop + faults.duplicate + faults.reorder + faults.corrupt > 1.0)
    throw CLI::ValidationError("--drop/--duplicate/--reorder/--corrupt",
                               "probabilities add up to more than 1");
}

}  // namespace

int main(int argc, char** argv) {
  rsg::app::init_logging("rsg_sim");
  rsg::app::StopOnSignal::block_stop_signals();
  CLI::App app{"Simulated Franka Panda: streams SEND_BUF frames (docs/protocol.md) over UDP.", "rsg_sim"};
  app.footer(std::string(kScheduleHelp) +
             "\n\nRuns until --count/--duration or SIGINT/SIGTERM. Exit status: 0 success, 1 runtime "
             "error (socket, file), 2 usage error (flags, address, replay file).");
  Options options;
  rsg::tools::sim::SimConfig config;
  add_options(app, options, config);
  // Checks across options, at the end of parsing: a usage error like any other (exit status 2).
  app.final_callback([&] {
    config.schedule = build_schedule(options);
    check_probabilities(config.faults);
    config.pause = std::chrono::milliseconds(options.pause_ms);
  });

  return rsg::app::run_main(app, argc, argv, [&] {
    if (!options.replay_path.empty()) return run_replay(options);
    const rsg::transport::Endpoint peer = rsg::transport::Endpoint::parse(options.to);
    rsg::transport::UdpSocket socket = rsg::transport::UdpSocket::for_sending_to(peer);
    rsg::tools::sim::UdpLink link(socket, peer);
    rsg::tools::sim::Simulator sim(config);

    std::ofstream record;
    if (!options.record_path.empty()) {
      record.open(options.record_path);
      if (!record) throw rsg::EnvironmentError("cannot write '" + options.record_path + "'");
      sim.record_to(&record);
    }

    std::optional<rsg::capture::PcapWriter> pcap;
    if (!options.pcap_path.empty()) link.capture_to(&pcap.emplace(options.pcap_path));

    rsg::tools::sim::StreamLimits limits;
    limits.count = options.count;
    if (options.duration_s)
      limits.duration = std::chrono::duration_cast<std::chrono::nanoseconds>(
          std::chrono::duration<double>(*options.duration_s));

    std::atomic<bool> stop{false};
    const rsg::app::StopOnSignal signals([&stop] { stop = true; });
    spdlog::info("sending to {} at {} Hz", peer.to_string(), config.rate_hz);
    rsg::tools::sim::stream(sim, link, limits, stop);

    spdlog::info("{}", sim.report().summary());
    if (!options.report_path.empty()) {
      std::ofstream report(options.report_path);
      report << sim.report().to_json() << "\n";
      if (!report) throw rsg::EnvironmentError("cannot write '" + options.report_path + "'");
    }
    if (pcap) pcap->flush();
    if (record.is_open() && !record.flush())
      throw rsg::EnvironmentError("cannot write '" + options.record_path + "'");
    return kExitOk;
  });
}
