// The main() skeleton every rsg executable shares (the tools and rsg_gateway): one logger, the exit
// statuses, and error reporting, so that scripts can tell a usage mistake (2) from a failure at run
// time (1) the same way for all, and every line on stderr says which program wrote it.
//
//   int main(int argc, char** argv) {
//     rsg::app::init_logging("rsg_echo");
//     rsg::app::StopOnSignal::block_stop_signals();
//     CLI::App app{...};
//     ...
//     return rsg::app::run_main(app, argc, argv, [&] { ...; return rsg::app::kExitOk; });
//   }
//
// No main catches and maps on its own: a check the command line cannot express is a CLI11 callback
// (app.final_callback, an option's check) that throws a CLI::ParseError, or setup code in the body
// that throws rsg::InputError; either way the exit status is 2.
#pragma once

#include <spdlog/pattern_formatter.h>
#include <spdlog/sinks/stdout_sinks.h>
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <cctype>
#include <exception>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>

#include "app/exit_status.hpp"
#include "rsg/error.hpp"

namespace rsg::app {

namespace internal {

// The `%*` of kToolPattern: "warning: " before a warning, nothing otherwise (an error is the
// tool's last word and needs no label; an info line is what the tool did).
class WarningLabel final : public spdlog::custom_flag_formatter {
 public:
  void format(const spdlog::details::log_msg& message, const std::tm& /*time*/,
              spdlog::memory_buf_t& out) override {
    if (message.level != spdlog::level::warn) return;
    constexpr std::string_view kLabel = "warning: ";
    out.append(kLabel.data(), kLabel.data() + kLabel.size());
  }
  std::unique_ptr<custom_flag_formatter> clone() const override { return std::make_unique<WarningLabel>(); }
};

}  // namespace internal

/// Makes spdlog's default logger the executable's: every line on stderr, as "<tool>: <message>"
/// ("<tool>: warning: <message>" for a warning), at level info. Call it first in main().
inline void init_logging(std::string_view tool) {
  auto logger =
      std::make_shared<spdlog::logger>(std::string(tool), std::make_shared<spdlog::sinks::stderr_sink_mt>());
  auto formatter = std::make_unique<spdlog::pattern_formatter>();
  formatter->add_flag<internal::WarningLabel>('*').set_pattern("%n: %*%v");
  logger->set_formatter(std::move(formatter));
  logger->flush_on(spdlog::level::trace);  // a line is written when it is logged, as std::cerr did
  spdlog::set_default_logger(std::move(logger));
}

/// For a long-running process once it has started (rsg_gateway): each line also carries its time
/// and level, "[2026-11-24 23:31:50.262] [rsg_gateway] [info] ...", for a log read afterwards.
inline void log_with_timestamps() { spdlog::set_pattern("[%Y-%m-%d %H:%M:%S.%e] [%n] [%l] %v"); }

/// `--log-level LEVEL` (trace, debug, info, warn, error, off; any case), as rsg_gateway's: sets the
/// level of what the tool logs as soon as the flag is parsed.
inline void add_log_level_option(CLI::App& app) {
  app.add_option_function<std::string>(
         "--log-level",
         [](const std::string& level) {
           std::string lower = level;
           for (char& c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
           spdlog::set_level(spdlog::level::from_str(lower));
         },
         "What to log: trace, debug, info, warn, error or off (default info)")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "off"}, CLI::ignore_case));
}

/// Adds to every unsigned option of `app`, its option groups and subcommands a check that the value
/// is not negative: CLI11 2.1 converts "-1" to the largest unsigned value without a word.
inline void refuse_negative_unsigned(CLI::App& app) {
  for (CLI::Option* option : app.get_options())
    if (option->get_type_name().starts_with("UINT"))
      option->check(CLI::Validator(
          [](const std::string& value) {
            const auto first = value.find_first_not_of(" \t");
            return first != std::string::npos && value[first] == '-' ? "'" + value + "' is negative"
                                                                     : std::string();
          },
          "", "not negative"));
  for (CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; }))  // option groups too
    refuse_negative_unsigned(*sub);
}

/// Parses the command line; returns the exit status when the tool must stop here (--help: 0, with
/// the help on stdout; a parse error: 2, logged as "<tool>: <what> (see --help)"), or nothing to go on.
inline std::optional<int> parse_command_line(CLI::App& app, int argc, char** argv) {
  refuse_negative_unsigned(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& error) {
    if (error.get_exit_code() == 0) {  // --help
      app.exit(error);
      return kExitOk;
    }
    spdlog::error("{} (see --help)", error.what());
    return kExitUsage;
  }
  return std::nullopt;
}

/// The one mapping from what setup code throws to an exit status (CONTRIBUTING.md, "Errors"):
/// the user's input (rsg::InputError: a bad file, profile, view or address) is 2, everything else
/// (rsg::EnvironmentError: DDS, sockets, files; or anything unexpected) is 1.
inline int exit_status_of(const std::exception& error) noexcept {
  const auto* rsg_error = dynamic_cast<const rsg::Error*>(&error);
  return rsg_error != nullptr && rsg_error->kind() == rsg::Error::Kind::kInput ? kExitUsage : kExitFailure;
}

/// Runs `body` (which returns the exit status) and turns what it throws into an error logged as
/// "<tool>: <what>" (init_logging) and exit_status_of() it.
template <class Body>
int run_reporting_errors(Body&& body) {
  try {
    return std::forward<Body>(body)();
  } catch (const std::exception& error) {
    // The reason for the exit status is written even under `--log-level off`.
    if (!spdlog::should_log(spdlog::level::err)) spdlog::set_level(spdlog::level::err);
    spdlog::error("{}", error.what());
    return exit_status_of(error);
  }
}

/// The rest of main() once the command line is described: parses it (parse_command_line), then
/// runs `body`, which returns the exit status, through run_reporting_errors.
template <class Body>
int run_main(CLI::App& app, int argc, char** argv, Body&& body) {
  if (const auto exit_status = parse_command_line(app, argc, argv)) return *exit_status;
  return run_reporting_errors(std::forward<Body>(body));
}

}  // namespace rsg::app
