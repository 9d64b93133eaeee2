#include "gateway/realtime.hpp"

#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>
#include <sys/resource.h>

#include <cerrno>
#include <optional>
#include <string>
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

// Each step below returns what was refused, and why; nothing when it was done.
using Refusal = std::optional<std::string>;

Refusal pin(int cpu) {
  if (cpu >= CPU_SETSIZE)
    return "CPU " + std::to_string(cpu) + " not pinned: beyond the " + std::to_string(CPU_SETSIZE) +
           " CPUs Linux's affinity calls can name";
  cpu_set_t set;
  CPU_ZERO(&set);
  CPU_SET(cpu, &set);
  if (const int error = ::pthread_setaffinity_np(::pthread_self(), sizeof set, &set); error != 0)
    return "CPU " + std::to_string(cpu) + " not pinned: " + describe(error) +
           " (this process may run on CPUs " + allowed_cpus() + ")";
  return std::nullopt;
}

Refusal lock_memory() {
  // MCL_FUTURE as well: Fast DDS and the loaned samples may still map memory after start-up.
  if (::mlockall(MCL_CURRENT | MCL_FUTURE) != 0)
    return "memory not locked: mlockall: " + describe(errno) +
           " (needs CAP_IPC_LOCK or a memlock limit above the process's size; the limit is " +
           limit_text(RLIMIT_MEMLOCK) + " bytes)";
  return std::nullopt;
}

Refusal make_fifo(int priority) {
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
    return "SCHED_FIFO priority " + std::to_string(priority) + " refused: " + why;
  }
  return std::nullopt;
}

}  // namespace

RealtimeOutcome enter_realtime(const RealtimeRequest& request) {
  RealtimeOutcome outcome;
  // True when the step was done; else its refusal joins the outcome's problems.
  const auto done = [&outcome](const Refusal& refusal) {
    if (!refusal) return true;
    outcome.problems += (outcome.problems.empty() ? "" : "; ") + *refusal;
    return false;
  };
  if (request.cpu >= 0) outcome.pinned = done(pin(request.cpu));
  if (request.priority > 0) {
    // Memory first: faulting in every page of the process takes a while and should not run at
    // real-time priority, ahead of everything else on that CPU.
    outcome.locked = done(lock_memory());
    outcome.fifo = done(make_fifo(request.priority));
  }
  return outcome;
}

}  // namespace rsg::gateway
