// Real-time mode of the ingress thread: SCHED_FIFO, one pinned CPU, and the process's memory
// locked, so that a 1 kHz stream is not delayed by ordinary processes, migrations or page faults.
//
// What each part needs (Linux):
//   --rt-priority N   pthread_setschedparam(SCHED_FIFO, N): CAP_SYS_NICE, or an RLIMIT_RTPRIO of
//                     at least N (/etc/security/limits.conf: `robot - rtprio 80`;
//                     docker run --cap-add SYS_NICE --ulimit rtprio=99).
//                     It also asks for mlockall(MCL_CURRENT | MCL_FUTURE): CAP_IPC_LOCK, or an
//                     RLIMIT_MEMLOCK above the process's size (limits.conf: `robot - memlock
//                     unlimited`; docker run --cap-add IPC_LOCK or --ulimit memlock=-1). Prefer
//                     unlimited: MCL_FUTURE locks later mappings too, and past a finite limit
//                     they fail.
//   --cpu CPU         pthread_setaffinity_np: no privilege, only a CPU the process may run on
//                     (its cpuset: taskset, systemd CPUAffinity=, docker --cpuset-cpus).
//
// A refusal is never fatal: the thread keeps whatever was refused (normal scheduling, any CPU,
// pageable memory) and the caller logs one warning saying what and why.
//
// Threads inherit policy and affinity from the thread that creates them, so call this after the
// DDS entities (and with them Fast DDS's threads) exist.
#pragma once

#include <string>

namespace rsg::gateway {

struct RealtimeRequest {
  int priority = 0;  ///< SCHED_FIFO priority, 1..99; 0: normal scheduling and no memory locking
  int cpu = -1;      ///< the one CPU to run on; -1: any

  bool any() const { return priority > 0 || cpu >= 0; }
};

struct RealtimeOutcome {
  bool fifo = false;    ///< the calling thread now runs SCHED_FIFO at the requested priority
  bool pinned = false;  ///< the calling thread now runs on the requested CPU only
  bool locked = false;  ///< the process's memory, present and future, is locked
  /// Empty when everything requested took effect; else one line: what was refused, why, and
  /// which privilege would grant it.
  std::string problems;
};

/// Applies `request` to the calling thread (priority, CPU) and to the process (memory locking).
RealtimeOutcome enter_realtime(const RealtimeRequest& request);

}  // namespace rsg::gateway
