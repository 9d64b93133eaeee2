#include "realtime.hpp"

#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>
#include <sys/resource.h>

#include <cerrno>
#include <system_error>

namespace rsg::gateway {
namespace {

std::string describe(int error) { return std::error_code(error, std::generic_category()).message(); }

std::string limit_text(int resource) {
  rlimit limit{};
  if (::getrlimit(resource, &limit) != 0) return "unknown";
  return limit.rlim_cur == RLIM_INFINITY ? "unlimited" : std::to_string(limit.rlim_cur);
}

// "0-3,6": the CPUs this process may run on, for a message naming a CPU outside them.
std::string allowed_cpus() {
  cpu_set_t set;
  CPU_ZERO(&set);
  if (::sched_getaffinity(0, sizeof set, &set) != 0) return "unknown";
  std::string text;
  for (int cpu = 0; cpu < CPU_SETSIZE; ++cpu) {
    if (!CPU_ISSET(cpu, &set)) continue;
    int last = cpu;
    while (last + 1 < CPU_SETSIZE && CPU_ISSET(last + 1, &set)) ++last;
    text += (text.empty() ? "" : ",") + std::to_string(cpu) + (last > cpu ? "-" + std::to_string(last) : "");
    cpu = last;
  }
  return text;
}

void add(std::string& problems, const std::string& problem) {
  problems += (problems.empty() ? "" : "; ") + problem;
}

bool pin(int cpu, std::string& problems) {
  if (cpu >= CPU_SETSIZE) {
    add(problems, "CPU " + std::to_string(cpu) + " not pinned: beyond the " + std::to_string(CPU_SETSIZE) +
                      " CPUs Linux's affinity calls can name");
    return false;
  }
  cpu_set_t set;
  CPU_ZERO(&set);
  CPU_SET(cpu, &set);
  if (const int error = ::pthread_setaffinity_np(::pthread_self(), sizeof set, &set); error != 0) {
    add(problems, "CPU " + std::to_string(cpu) + " not pinned: " + describe(error) +
                      " (this process may run on CPUs " + allowed_cpus() + ")");
    return false;
  }
  return true;
}

bool lock_memory(std::string& problems) {
  // MCL_FUTURE as well: Fast DDS and the loaned samples may still map memory after start-up.
  if (::mlockall(MCL_CURRENT | MCL_FUTURE) != 0) {
    add(problems, "memory not locked: mlockall: " + describe(errno) +
                      " (needs CAP_IPC_LOCK or a memlock limit above the process's size; the limit is " +
                      limit_text(RLIMIT_MEMLOCK) + " bytes)");
    return false;
  }
  return true;
}

bool make_fifo(int priority, std::string& problems) {
  sched_param parameters{};
  parameters.sched_priority = priority;
  if (const int error = ::pthread_setschedparam(::pthread_self(), SCHED_FIFO, &parameters); error != 0) {
    std::string why = describe(error);
    if (error == EPERM)
      why += " (needs CAP_SYS_NICE or an rtprio limit of at least " + std::to_string(priority) +
             "; the limit is " + limit_text(RLIMIT_RTPRIO) + ")";
    else if (error == EINVAL)
      why += " (SCHED_FIFO priorities are " + std::to_string(::sched_get_priority_min(SCHED_FIFO)) + ".." +
             std::to_string(::sched_get_priority_max(SCHED_FIFO)) + ")";
    add(problems, "SCHED_FIFO priority " + std::to_string(priority) + " refused: " + why);
    return false;
  }
  return true;
}

}  // namespace

RealtimeOutcome enter_realtime(const RealtimeRequest& request) {
  RealtimeOutcome outcome;
  if (request.cpu >= 0) outcome.pinned = pin(request.cpu, outcome.problems);
  if (request.priority > 0) {
    // Memory first: faulting in every page of the process takes a while and should not run at
    // real-time priority, ahead of everything else on that CPU.
    outcome.locked = lock_memory(outcome.problems);
    outcome.fifo = make_fifo(request.priority, outcome.problems);
  }
  return outcome;
}

}  // namespace rsg::gateway
