// rsg_gateway: raw SEND_BUF frames over UDP <-> RobotState DDS samples. See gateway.hpp.
//
// Signals: SIGINT and SIGTERM stop it (final stats written), SIGUSR1 asks for a flight-recorder dump,
// SIGHUP re-reads the configuration (--config and the flags over it) and applies what can change
// while running (allow-from, log-level; Gateway::reload), naming the rest as needing a restart.
//
// Exit status (src/app/tool_main.hpp, as every rsg executable): 0 after SIGINT/SIGTERM, 2 when the
// configuration (flags, file, profiles, addresses) is unusable, 1 when the machine refuses (the port
// is taken, DDS refuses an entity); nothing is left running then. A refused real-time setting
// (--rt-priority, --cpu) is a warning, not a failure.
#include <fcntl.h>
#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <sys/stat.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <array>
#include <atomic>
#include <cerrno>
#include <cstdio>
#include <string>

#include "app/stop_on_signal.hpp"
#include "app/tool_main.hpp"
#include "gateway/config.hpp"
#include "gateway/config_check.hpp"
#include "gateway/errno_text.hpp"
#include "gateway/gateway.hpp"
#include "gateway/journal_log.hpp"
#include "gateway/service_notifier.hpp"
#include "gateway/version.hpp"
#include "rsg/error.hpp"

namespace {

using rsg::app::kExitOk;
using rsg::app::StopOnSignal;
using rsg::gateway::GatewayConfig;

constexpr const char* kRealtimeHelp = R"(Real-time mode applies to the ingress thread (the main thread):
  --rt-priority N  SCHED_FIFO at N needs CAP_SYS_NICE or `USER - rtprio N` in
                   /etc/security/limits.conf; the mlockall that comes with it needs CAP_IPC_LOCK
                   or `USER - memlock unlimited`. Docker: --cap-add SYS_NICE --cap-add IPC_LOCK
                   --ulimit rtprio=99 --ulimit memlock=-1
  --cpu CPU        needs only a CPU of the process's cpuset (taskset, docker --cpuset-cpus).
Whatever is refused is logged as one warning and the gateway runs without it.)";

// What the command line says besides the configuration keys.
struct Command {
  std::string config_file;
  std::string instance;     ///< --instance: the unit's instance name, whose defaults go under the file
  bool check_only = false;  ///< --check-config: check everything, start nothing
};

// Every config key becomes a long flag bound to `config`; CLI11 writes only the flags that are
// given, so binding them to a configuration read from the file makes flags override the file.
void add_config_flags(CLI::App& app, GatewayConfig& config, Command& command) {
  app.add_option("--config", command.config_file,
                 "YAML file with the same keys as the long flags (flags win)");
  app.add_option("--instance", command.instance,
                 "The instance NAME of the systemd unit rsg-gateway@NAME: partition NAME, stats-file "
                 "/run/rsg/NAME/stats.json and pcap-dir /var/lib/rsg/NAME (the unit's directories) unless "
                 "the file or a flag sets them");
  app.add_flag("--check-config,--check", command.check_only,
               "Check the configuration (flags, --config file, XML profiles and the files they name, "
               "addresses and ports, files to write) the way a start does, print what it found and exit: "
               "0 when the gateway would start with it, 2 when the configuration is wrong, 1 when this "
               "host refuses what it needs (an address not on it, a port in use); binds the ports and "
               "closes them at once, enables no DDS participant, and does not require the directories "
               "the unit creates at start");
  for (const rsg::gateway::ConfigKey& key : rsg::gateway::config_keys()) {
    const std::string flag = "--" + std::string(key.name);
    const std::string help(key.help);
    std::visit(
        [&](auto member) {
          if constexpr (std::is_same_v<decltype(member), bool GatewayConfig::*>) {
            app.add_flag(flag, config.*member, help);  // --ros2, or --ros2=false over a YAML `true`
          } else {
            CLI::Option* option = app.add_option(flag, config.*member, help);
            if constexpr (std::is_same_v<decltype(member), std::vector<std::string> GatewayConfig::*>)
              option->delimiter(',');
            else
              option->capture_default_str();
          }
        },
        key.member);
  }
}

// The file, read once through one descriptor. A file that changes while it is read (its size or
// time moves) is refused rather than parsed half: docs/configuration.md says how to replace it
// atomically (write a copy, rename it over). On a reload, a file that does not end with a newline
// is refused too: a file cut while written ends mid-line, an editor's always ends with one.
std::string read_file(const std::string& path, bool reloading) {
  using rsg::gateway::errno_text;
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw rsg::InputError("--config: cannot read " + path + ": " + errno_text(errno));
  struct Close {
    int fd;
    ~Close() { ::close(fd); }
  } const closing{fd};
  struct ::stat before {};
  if (::fstat(fd, &before) != 0)
    throw rsg::InputError("--config: cannot read " + path + ": " + errno_text(errno));
  // A directory opens and reads as nothing: it would be an empty configuration.
  if (S_ISDIR(before.st_mode))
    throw rsg::InputError("--config: '" + path + "' is a directory: " + errno_text(EISDIR));
  std::string text;
  std::array<char, 8192> chunk{};
  for (;;) {
    const ::ssize_t got = ::read(fd, chunk.data(), chunk.size());
    if (got < 0 && errno == EINTR) continue;
    if (got < 0) throw rsg::InputError("--config: cannot read " + path + ": " + errno_text(errno));
    if (got == 0) break;
    text.append(chunk.data(), static_cast<std::size_t>(got));
  }
  struct ::stat after {};
  const bool changed = ::fstat(fd, &after) != 0 || after.st_size != before.st_size ||
                       after.st_mtim.tv_sec != before.st_mtim.tv_sec ||
                       after.st_mtim.tv_nsec != before.st_mtim.tv_nsec ||
                       static_cast<::off_t>(text.size()) != after.st_size;
  if (changed)
    throw rsg::InputError("--config: " + path +
                          " changed while it was read: not used (replace it atomically: write a copy next "
                          "to it, then rename the copy over it)");
  if (reloading && !text.empty() && text.back() != '\n')
    throw rsg::InputError("--config: " + path +
                          " does not end with a newline: is it still being written? Not used (replace it "
                          "atomically: write a copy next to it, then rename the copy over it)");
  return text;
}

// The configuration: the instance's defaults (--instance), the file (--config) over them, the
// flags over both.
// @throws rsg::InputError when the file cannot be read or does not parse, or the instance is no name.
GatewayConfig read_config(const Command& command, const GatewayConfig& flags_only, int argc, char** argv,
                          bool reloading = false) {
  if (command.config_file.empty() && command.instance.empty()) return flags_only;
  GatewayConfig config;
  if (!command.instance.empty()) {
    auto defaults = rsg::gateway::instance_defaults(command.instance);
    if (const auto* why = std::get_if<std::string>(&defaults)) throw rsg::InputError(*why);
    config = std::get<GatewayConfig>(std::move(defaults));
  }
  if (const std::string& file = command.config_file; !file.empty()) {
    const rsg::gateway::ConfigResult parsed =
        rsg::gateway::parse_gateway_config(read_file(file, reloading), config);
    if (!parsed) {
      const auto& error = parsed.error();
      throw rsg::InputError(file + (error.line > 0 ? ":" + std::to_string(error.line) : std::string()) +
                            ": " + error.message);
    }
    config = parsed.config();
  }
  CLI::App app("rsg_gateway", "rsg_gateway");
  Command ignored;
  add_config_flags(app, config, ignored);
  app.parse(argc, argv);  // accepted once already
  return config;
}

}  // namespace

int main(int argc, char** argv) {
  rsg::app::init_logging("rsg_gateway");
  rsg::gateway::use_journal_priorities();  // under systemd: each line's level as its journal priority
  StopOnSignal::block_stop_signals(/*with_service_signals=*/true);
  CLI::App app("rsg_gateway: robot-state frames over UDP <-> RobotState DDS samples", "rsg_gateway");
  app.footer(kRealtimeHelp);
  app.set_version_flag("--version",
                       fmt::format("rsg_gateway {} (Fast DDS {})", rsg::gateway::rsg_version(),
                                   rsg::gateway::fastdds_version()),
                       "Print rsg's version and the Fast DDS version it was built with, and exit");
  GatewayConfig flags_only;
  Command command;
  add_config_flags(app, flags_only, command);

  return rsg::app::run_main(app, argc, argv, [&] {
    const GatewayConfig config = read_config(command, flags_only, argc, argv);
    // Every value is checked before any is used: a log level spdlog does not know would otherwise
    // turn the log off, this message with it.
    if (auto problem = rsg::gateway::check_config(config)) throw rsg::InputError(*problem);
    spdlog::set_level(spdlog::level::from_str(rsg::gateway::log_level_name(config)));
    if (config.log_format == "json") rsg::gateway::use_json_log_lines();  // every line from here on
    const rsg::gateway::GatewaySetup setup = rsg::gateway::prepare(
        config, command.check_only ? rsg::gateway::PrepareFor::kCheck : rsg::gateway::PrepareFor::kStart);
    // At a start too: Fast DDS refuses a participant whose security file is missing without naming it.
    rsg::gateway::check_profile_files(config);
    if (command.check_only) {
      rsg::gateway::check_entity_profiles_offline(config);
      // Last: what a start does first with the configuration.
      const std::vector<std::string> notes = rsg::gateway::check_bindings(setup, command.config_file);
      std::fputs(rsg::gateway::describe_setup(setup, command.config_file, notes).c_str(), stdout);
      return kExitOk;
    }
    // SIGUSR1 asks for a flight-recorder dump: the loop takes it when it sees `dump`. SIGHUP's
    // configuration is read here, on the signal's thread (the loop never waits on a file), and
    // applied by the loop.
    std::atomic<bool> stop{false};
    std::atomic<bool> dump{false};
    rsg::gateway::PendingReload reload;
    const auto reread = [&] {
      try {
        reload.offer(read_config(command, flags_only, argc, argv, /*reloading=*/true));
      } catch (const std::exception& error) {  // a bad file must not end a running gateway
        reload.offer(std::string(error.what()));
      }
    };
    const StopOnSignal signals([&stop] { stop = true; },
                               StopOnSignal::ServiceSignals{[&dump] { dump = true; }, reread});
    rsg::gateway::Gateway gateway(setup);
    // Started: from here on a log of a running service, with times (but for the journal's own).
    if (config.log_format != "json") rsg::app::log_with_timestamps();
    rsg::gateway::enter_realtime_mode(config);
    rsg::gateway::ServiceNotifier systemd;  // READY, STATUS and the watchdog under a Type=notify unit
    gateway.run(stop, &dump, &systemd, &reload);
    return kExitOk;
  });
}
