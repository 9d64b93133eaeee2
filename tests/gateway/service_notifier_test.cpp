// ServiceNotifier against a real notification socket: a Unix datagram socket of the test's own,
// named by NOTIFY_SOCKET as systemd would, which libsystemd's sd_notify sends to.
#include "gateway/service_notifier.hpp"

#include <gtest/gtest.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <optional>
#include <string>

namespace rsg::gateway {
namespace {

using namespace std::chrono_literals;

// A bound Unix datagram socket in a fresh directory, as NOTIFY_SOCKET; unset again at the end.
class NotifySocket {
 public:
  NotifySocket() {
    char dir_template[] = "/tmp/rsg_notify_XXXXXX";
    dir_ = ::mkdtemp(dir_template);
    path_ = dir_ + "/notify";
    fd_ = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    sockaddr_un address{};
    address.sun_family = AF_UNIX;
    path_.copy(address.sun_path, sizeof address.sun_path - 1);
    if (::bind(fd_, reinterpret_cast<const sockaddr*>(&address), sizeof address) != 0)
      throw std::runtime_error("cannot bind " + path_);
    ::setenv("NOTIFY_SOCKET", path_.c_str(), 1);
  }
  ~NotifySocket() {
    ::unsetenv("NOTIFY_SOCKET");
    ::unsetenv("WATCHDOG_USEC");
    ::unsetenv("WATCHDOG_PID");
    ::close(fd_);
    std::filesystem::remove_all(dir_);
  }
  NotifySocket(const NotifySocket&) = delete;
  NotifySocket& operator=(const NotifySocket&) = delete;

  /// The next datagram, or nothing within `timeout`.
  std::optional<std::string> next(std::chrono::milliseconds timeout = 2000ms) {
    pollfd waiting{fd_, POLLIN, 0};
    if (::poll(&waiting, 1, static_cast<int>(timeout.count())) != 1) return std::nullopt;
    char buffer[4096];
    const ssize_t size = ::recv(fd_, buffer, sizeof buffer, 0);
    if (size < 0) return std::nullopt;
    return std::string(buffer, static_cast<std::size_t>(size));
  }

 private:
  std::string dir_;
  std::string path_;
  int fd_ = -1;
};

status::GatewayStats streaming() {
  status::GatewayStats stats;
  stats.link_up = true;
  stats.source = "127.0.0.1:40000";
  stats.rate_hz = 1000;
  stats.state_readers = 2;
  return stats;
}

TEST(ServiceNotifier, WithoutNotifySocketItIsInactiveAndSendsNothing) {
  ::unsetenv("NOTIFY_SOCKET");
  ServiceNotifier notifier;
  EXPECT_FALSE(notifier.active());
  EXPECT_FALSE(notifier.watchdog_interval().has_value());
  notifier.started(streaming(), true);  // does nothing, and does not fail
  notifier.turned(Clock::now());
}

TEST(ServiceNotifier, StartedSendsReadyWithAStatusLine) {
  NotifySocket socket;
  ServiceNotifier notifier;
  ASSERT_TRUE(notifier.active());
  notifier.started(streaming(), true);
  EXPECT_EQ(socket.next(), "READY=1\nSTATUS=link up from 127.0.0.1:40000 at 1000.0 Hz, 2 readers");
  status::GatewayStats down;
  notifier.status(down, true);
  EXPECT_EQ(socket.next(), "STATUS=link down, 0 readers");
  notifier.stopping();
  EXPECT_EQ(socket.next(), "STOPPING=1");
}

TEST(ServiceNotifier, TheStatusLineSaysFirstThatRobotsAreMixed) {
  status::GatewayStats stats = streaming();
  stats.other_state_writers = 1;
  EXPECT_EQ(
      service_status_line(stats, true, {}),
      "ROBOTS MIXED: 1 other writer of the state topic in this partition; link up from 127.0.0.1:40000 at "
      "1000.0 Hz, 2 readers");
}

TEST(ServiceNotifier, TheStatusLineNamesWhatKeepsTheLinkDown) {
  NotifySocket socket;
  ServiceNotifier notifier;
  status::GatewayStats stats;
  stats.ingress.rejected_source = 5;  // before the start: not this period's
  notifier.started(stats, true);
  EXPECT_EQ(socket.next(), "READY=1\nSTATUS=link down, 0 readers");
  stats.ingress.rejected_source += 1000;
  notifier.status(stats, true);
  EXPECT_EQ(socket.next(),
            "STATUS=link down: ignoring 1000 datagrams/s from outside --allow-from, 0 readers");
  stats.ingress.invalid[status::invalid_index(wire::ErrorCategory::kBadCrc)] += 20;
  notifier.status(stats, true);
  EXPECT_EQ(socket.next(), "STATUS=link down: rejecting 20 invalid frames/s (bad_crc=20), 0 readers");
  notifier.status(stats, true);  // nothing new: nothing to name
  EXPECT_EQ(socket.next(), "STATUS=link down, 0 readers");
  status::GatewayStats up = streaming();
  up.ingress = stats.ingress;
  up.ingress.rejected_source += 3;
  notifier.status(up, true);
  EXPECT_EQ(
      socket.next(),
      "STATUS=link up from 127.0.0.1:40000 at 1000.0 Hz, ignoring 3 datagrams/s from outside --allow-from, "
      "2 readers");
}

TEST(ServiceNotifier, WithoutAWatchdogTurnsSendNothing) {
  NotifySocket socket;
  ServiceNotifier notifier;
  EXPECT_FALSE(notifier.watchdog_interval().has_value());
  notifier.turned(Clock::now());
  EXPECT_EQ(socket.next(200ms), std::nullopt);
}

TEST(ServiceNotifier, TurnsPingTheWatchdogAtMostEveryHalfInterval) {
  NotifySocket socket;
  ::setenv("WATCHDOG_USEC", "2000000", 1);
  ::setenv("WATCHDOG_PID", std::to_string(::getpid()).c_str(), 1);
  ServiceNotifier notifier;
  ASSERT_EQ(notifier.watchdog_interval(), std::chrono::seconds(2));
  const auto start = Clock::now();
  notifier.turned(start);
  EXPECT_EQ(socket.next(), "WATCHDOG=1");
  notifier.turned(start + 100ms);
  notifier.turned(start + 999ms);
  EXPECT_EQ(socket.next(200ms), std::nullopt) << "pinged again before half the interval";
  notifier.turned(start + 1000ms);
  EXPECT_EQ(socket.next(), "WATCHDOG=1");
}

TEST(ServiceNotifier, AWatchdogMeantForAnotherProcessIsNotPinged) {
  NotifySocket socket;
  ::setenv("WATCHDOG_USEC", "2000000", 1);
  ::setenv("WATCHDOG_PID", std::to_string(::getpid() + 1).c_str(), 1);
  ServiceNotifier notifier;
  EXPECT_FALSE(notifier.watchdog_interval().has_value());
  notifier.turned(Clock::now());
  EXPECT_EQ(socket.next(200ms), std::nullopt);
}

}  // namespace
}  // namespace rsg::gateway
