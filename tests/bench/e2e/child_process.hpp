// A child process (the gateway, the bench's own writer role, ddsperf) that cannot outlive the run.
//
// The destructor stops it (SIGTERM, then SIGKILL) and reaps it; should the bench die without
// unwinding (SIGKILL, a crash), the kernel sends the child SIGTERM (PR_SET_PDEATHSIG).
#pragma once

#include <sys/types.h>

#include <chrono>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace rsg::bench {

class ChildProcess {
 public:
  /// Starts `argv` (argv[0] a path) with stdout and stderr appended to `log`. Must be called from
  /// the thread that lives longest (the main thread): the death signal follows the spawning thread.
  /// Throws std::system_error when it cannot fork.
  ChildProcess(const std::vector<std::string>& argv, const std::filesystem::path& log);
  ~ChildProcess();
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;

  pid_t pid() const { return pid_; }
  /// True until the child has exited (reaps it when it has).
  bool running();
  /// Waits up to `timeout` for the child to exit by itself; its exit status (128 + signal when
  /// killed), or nothing while it still runs.
  std::optional<int> wait_for(std::chrono::milliseconds timeout);
  /// SIGTERM, then SIGKILL when it has not exited within `grace`. Returns the exit status.
  int stop(std::chrono::milliseconds grace = std::chrono::seconds(3));

 private:
  pid_t pid_ = -1;
  std::optional<int> status_;
};

}  // namespace rsg::bench
