// The metrics endpoint over a real loopback TCP connection: what each path answers, and what a
// client that misbehaves gets. The gateway under such clients at 1 kHz: integration.metrics_abuse.
#include "gateway/metrics_server.hpp"

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <string>

#include "rsg/error.hpp"

namespace rsg::gateway {
namespace {

using namespace std::chrono_literals;

MetricsSnapshot snapshot(bool link_up) {
  MetricsSnapshot s;
  s.has_ingress = true;
  s.gateway = "robot1";
  s.stats.link_up = link_up;
  s.stats.ingress.published = 5;
  s.taken = Clock::now();
  return s;
}

MetricsServer::Options loopback() {
  MetricsServer::Options options;
  options.listen = transport::Endpoint::parse("127.0.0.1:0");
  options.max_connections = 4;
  return options;
}

// A blocking client connection, from `source` (any 127.0.0.0/8 address: another client).
class Client {
 public:
  explicit Client(std::uint16_t port, const char* source = "127.0.0.1")
      : fd_(::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0)) {
    sockaddr_in from{};
    from.sin_family = AF_INET;
    ::inet_pton(AF_INET, source, &from.sin_addr);
    if (::bind(fd_, reinterpret_cast<const sockaddr*>(&from), sizeof from) != 0)
      throw std::runtime_error("cannot bind");
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_port = htons(port);
    address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (::connect(fd_, reinterpret_cast<const sockaddr*>(&address), sizeof address) != 0)
      throw std::runtime_error("cannot connect");
  }
  ~Client() { ::close(fd_); }
  Client(const Client&) = delete;
  Client& operator=(const Client&) = delete;

  void send(const std::string& text) {
    ASSERT_EQ(::send(fd_, text.data(), text.size(), MSG_NOSIGNAL), ssize_t(text.size()));
  }

  /// Everything until the server closes or `timeout` passes without a byte.
  std::string read_all(std::chrono::milliseconds timeout = 3000ms) {
    std::string text;
    for (;;) {
      pollfd waiting{fd_, POLLIN, 0};
      if (::poll(&waiting, 1, static_cast<int>(timeout.count())) != 1) return text;
      char buffer[4096];
      const ssize_t size = ::recv(fd_, buffer, sizeof buffer, 0);
      if (size <= 0) {
        closed_ = true;
        return text;
      }
      text.append(buffer, static_cast<std::size_t>(size));
    }
  }

  /// Whether the server closed the connection during the last read_all.
  bool closed() const { return closed_; }

 private:
  int fd_;
  bool closed_ = false;
};

std::string get(std::uint16_t port, const std::string& target, const std::string& method = "GET") {
  Client client(port);
  client.send(method + " " + target + " HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n");
  return client.read_all();
}

TEST(MetricsServer, MetricsAnswersTheLastPublishedSnapshotInTheExpositionFormat) {
  MetricsServer server(loopback(), snapshot(true));
  auto response = get(server.port(), "/metrics");
  EXPECT_TRUE(response.starts_with("HTTP/1.1 200 OK\r\n")) << response;
  EXPECT_NE(response.find("Content-Type: text/plain; version=0.0.4; charset=utf-8\r\n"), std::string::npos);
  EXPECT_NE(response.find("\nrsg_frames_published_total{gateway=\"robot1\"} 5\n"), std::string::npos);
  EXPECT_NE(response.find("\nprocess_cpu_seconds_total{gateway=\"robot1\"} "), std::string::npos);

  MetricsSnapshot later = snapshot(true);
  later.stats.ingress.published = 6;
  server.publish(later);
  response = get(server.port(), "/metrics?x=1");
  EXPECT_NE(response.find("\nrsg_frames_published_total{gateway=\"robot1\"} 6\n"), std::string::npos);
}

// /readyz (and /healthz, its older name) follow the link; /livez only the loop's snapshots.
TEST(MetricsServer, ReadyzAndHealthzFollowTheLinkLivezDoesNot) {
  MetricsServer server(loopback(), snapshot(true));
  for (const char* path : {"/livez", "/readyz", "/healthz"})
    EXPECT_TRUE(get(server.port(), path).starts_with("HTTP/1.1 200 OK\r\n")) << path;
  server.publish(snapshot(false));
  for (const char* path : {"/readyz", "/healthz"}) {
    const auto response = get(server.port(), path);
    EXPECT_TRUE(response.starts_with("HTTP/1.1 503 Service Unavailable\r\n")) << path << response;
    EXPECT_TRUE(response.ends_with("link down\n")) << path << response;
  }
  EXPECT_TRUE(get(server.port(), "/livez").starts_with("HTTP/1.1 200 OK\r\n"));
}

// A loop that stopped handing over snapshots: not alive, so not ready either.
TEST(MetricsServer, AStaleSnapshotFailsLivezAndReadyz) {
  MetricsSnapshot old = snapshot(true);
  old.taken = Clock::now() - std::chrono::seconds(10);
  MetricsServer server(loopback(), old);
  for (const char* path : {"/livez", "/readyz"}) {
    const auto response = get(server.port(), path);
    EXPECT_TRUE(response.starts_with("HTTP/1.1 503 Service Unavailable\r\n")) << path << response;
    EXPECT_TRUE(response.ends_with("the gateway's loop has not reported for too long\n")) << path << response;
  }
}

TEST(MetricsServer, OtherPathsAre404AndOtherMethods405) {
  MetricsServer server(loopback(), snapshot(true));
  EXPECT_TRUE(get(server.port(), "/").starts_with("HTTP/1.1 404 Not Found\r\n"));
  EXPECT_TRUE(get(server.port(), "/metrics/x").starts_with("HTTP/1.1 404 Not Found\r\n"));
  EXPECT_TRUE(get(server.port(), "/metrics", "POST").starts_with("HTTP/1.1 405 Method Not Allowed\r\n"));
}

TEST(MetricsServer, AHeaderOverTheLimitIsRefusedAndTheConnectionClosed) {
  MetricsServer server(loopback(), snapshot(true));
  Client client(server.port());
  client.send("GET /metrics HTTP/1.1\r\nX-Big: " + std::string(MetricsServer::kMaxRequestHeader, 'a') +
              "\r\n\r\n");
  const auto response = client.read_all();
  EXPECT_TRUE(response.starts_with("HTTP/1.1 431 ")) << response.substr(0, 100);
}

// The value of one rsg_http_connections_closed_total series in a /metrics answer, or -1.
long closed_count(const std::string& response, const std::string& reason) {
  const std::string key = "reason=\"" + reason + "\"} ";
  const auto at = response.find(key, response.find("\nrsg_http_connections_closed_total{"));
  return at == std::string::npos ? -1 : std::stol(response.substr(at + key.size()));
}

// Waits until the server has accepted what was connected (the counts are the I/O thread's).
void settle() { ::usleep(200000); }

TEST(MetricsServer, AtTheCapTheOldestWaitingConnectionMakesRoomForAProbe) {
  MetricsServer server(loopback(), snapshot(true));
  std::vector<std::unique_ptr<Client>> idle;
  for (int i = 0; i < 4; ++i) idle.push_back(std::make_unique<Client>(server.port()));
  settle();
  const auto probe = get(server.port(), "/healthz");
  EXPECT_TRUE(probe.starts_with("HTTP/1.1 200 OK\r\n")) << probe;
  EXPECT_EQ(idle.front()->read_all(1000ms), "");
  EXPECT_TRUE(idle.front()->closed()) << "the oldest idle connection was not the one closed";
  EXPECT_FALSE((idle.back()->read_all(100ms), idle.back()->closed()));
  EXPECT_GE(closed_count(get(server.port(), "/metrics"), "total_limit"),
            1);  // the probe (and this, if the probe is still open)
}

TEST(MetricsServer, OneClientAtItsCapClosesItsOwnOldestConnectionsNotOthers) {
  MetricsServer::Options options = loopback();
  options.max_connections = 8;
  options.max_connections_per_client = 2;
  MetricsServer server(options, snapshot(true));
  Client other1(server.port(), "127.0.0.3"), other2(server.port(), "127.0.0.3");
  std::vector<std::unique_ptr<Client>> attacker;
  for (int i = 0; i < 6; ++i) attacker.push_back(std::make_unique<Client>(server.port(), "127.0.0.2"));
  settle();
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(attacker[i]->read_all(500ms), "");
    EXPECT_TRUE(attacker[i]->closed()) << i;
  }
  EXPECT_FALSE((other1.read_all(100ms), other1.closed()));
  EXPECT_FALSE((other2.read_all(100ms), other2.closed()));
  Client probe(server.port(), "127.0.0.2");
  probe.send("GET /metrics HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n");
  EXPECT_EQ(closed_count(probe.read_all(), "per_client_limit"), 5);
}

TEST(MetricsServer, AClientThatNeverFinishesItsRequestIsClosedAfterTheHeaderTimeout) {
  MetricsServer::Options options = loopback();
  options.header_timeout = 300ms;
  MetricsServer server(options, snapshot(true));
  Client slow(server.port());
  slow.send("GET /metrics HTTP/1.1\r\n");  // and nothing more
  const auto start = std::chrono::steady_clock::now();
  EXPECT_EQ(slow.read_all(5000ms), "");
  EXPECT_TRUE(slow.closed()) << "the server still holds a request that never ends";
  EXPECT_LT(std::chrono::steady_clock::now() - start, 3s);
  EXPECT_EQ(closed_count(get(server.port(), "/metrics"), "header_timeout"), 1);
}

TEST(MetricsServer, AKeptAliveConnectionWithoutANextRequestIsClosedAfterTheIdleTimeout) {
  MetricsServer::Options options = loopback();
  options.idle_timeout = 300ms;
  MetricsServer server(options, snapshot(true));
  Client client(server.port());
  client.send("GET /healthz HTTP/1.1\r\nHost: x\r\n\r\n");
  const auto response = client.read_all(1500ms);
  EXPECT_TRUE(response.starts_with("HTTP/1.1 200 OK\r\n")) << response;
  EXPECT_TRUE(client.closed()) << "kept alive past the idle timeout";
  EXPECT_EQ(closed_count(get(server.port(), "/metrics"), "idle_timeout"), 1);
}

TEST(MetricsServer, APortThatIsTakenIsAnEnvironmentError) {
  MetricsServer first(loopback(), snapshot(true));
  MetricsServer::Options same = loopback();
  same.listen = transport::Endpoint::parse("127.0.0.1:" + std::to_string(first.port()));
  EXPECT_THROW(MetricsServer(same, snapshot(true)), EnvironmentError);
}

}  // namespace
}  // namespace rsg::gateway
