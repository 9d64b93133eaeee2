// Log lines with journal priorities: when stderr is connected to systemd's journal (the unit's
// JOURNAL_STREAM names stderr's device and inode), every line gets the syslog priority of its
// level as a "<N>" prefix, which journald takes as the entry's priority (SyslogLevelPrefix=, on
// by default) and strips: `journalctl -p warning` then shows warnings and errors only.
#pragma once

#include <spdlog/common.h>

namespace rsg::gateway {

/// The syslog priority of a spdlog level: error 3, warn 4, info 6, debug and trace 7 (critical 2).
int journal_priority(spdlog::level::level_enum level);

/// True when JOURNAL_STREAM ("DEV:INODE") names the file stderr is.
bool stderr_is_journal();

/// When stderr is the journal, makes the default logger prefix each line with its priority (the
/// pattern, set before or after, stays the logger's); otherwise does nothing. Call after the
/// logger is set up (rsg::tools::init_logging), before other threads log.
void use_journal_priorities();

}  // namespace rsg::gateway
