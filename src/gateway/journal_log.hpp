// How the running gateway's log lines look, on stderr or in systemd's journal.
//
// When stderr is connected to the journal (the unit's JOURNAL_STREAM names stderr's device and
// inode), every line gets the syslog priority of its level as a "<N>" prefix, which journald takes
// as the entry's priority (SyslogLevelPrefix=, on by default) and strips: `journalctl -p warning`
// then shows warnings and errors only. The journal stamps each entry itself, so the line carries
// no time of its own there: one timestamp per line in `journalctl`.
//
// `--log-format json` makes each line one JSON object (time, level, logger, message), for log
// shippers that parse lines; in the journal it has no `time` either.
#pragma once

#include <spdlog/common.h>
#include <spdlog/details/log_msg.h>

#include <string>

namespace rsg::gateway {

/// The syslog priority of a spdlog level: error 3, warn 4, info 6, debug and trace 7 (critical 2).
int journal_priority(spdlog::level::level_enum level);

/// True when JOURNAL_STREAM ("DEV:INODE") names the file stderr is.
bool stderr_is_journal();

/// When stderr is the journal, makes the default logger prefix each line with its priority and
/// leave the time to the journal, from now on and whatever pattern is set later; otherwise does
/// nothing. Call after the logger is set up (rsg::app::init_logging), before other threads log.
void use_journal_priorities();

/// `--log-format json`: from now on each line is one JSON object (json_log_line), with its time
/// unless it goes to the journal. Call before other threads log.
void use_json_log_lines();

/// One log line as a JSON object without its line feed: {"time":"2026-11-24T23:31:50.262Z",
/// "level":"info","logger":"rsg_gateway","message":"..."}; no "time" when `with_time` is false.
/// The time is UTC, to the millisecond.
std::string json_log_line(const spdlog::details::log_msg& message, bool with_time);

}  // namespace rsg::gateway
