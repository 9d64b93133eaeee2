// `--metrics HOST:PORT`: an HTTP endpoint (Boost.Beast, one I/O thread of its own) that answers
//   GET /metrics  the last MetricsSnapshot in Prometheus' text format (metrics.hpp)
//   GET /livez    200 while the gateway's loop hands over snapshots (the process works), else 503
//   GET /readyz   200 while also valid frames arrive within the link deadline, else 503
//   GET /healthz  /readyz, by its older name
// and 404 to any other path, 405 to any other method.
//
// The ingress thread never waits for the HTTP side: `publish` swaps in a new snapshot (an atomic
// shared pointer) and returns; the I/O thread formats it when a scraper asks. Bad clients cost the
// I/O thread only, and never keep /healthz from answering: request headers are capped
// (kMaxRequestHeader); a request must arrive whole within Options::header_timeout and the next one
// on a kept-alive connection start within Options::idle_timeout; connections are capped per client
// address and in total, and at a cap the oldest connection still waiting for its request makes
// room (app::ConnectionTable), so a probe that connects and asks at once is answered however many
// slow or idle connections are open. Each limit that bites is counted on /metrics
// (rsg_http_connections_closed_total{reason}) and logged at most once a minute.
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "gateway/metrics.hpp"
#include "rsg/transport/udp_socket.hpp"

namespace rsg::gateway {

class MetricsServer {
 public:
  struct Options {
    transport::Endpoint listen;  ///< port 0: any free port (see port())
    std::size_t max_connections = 32;
    std::size_t max_connections_per_client = 8;  ///< per client IP address
    /// From accept (or a kept-alive request's first byte) to the end of the request's header.
    std::chrono::milliseconds header_timeout = std::chrono::seconds(5);
    /// A kept-alive connection's wait for the first byte of its next request.
    std::chrono::milliseconds idle_timeout = std::chrono::seconds(15);
    /// A snapshot older than this makes /livez and /readyz answer 503: the loop that takes them is stuck.
    Clock::duration max_snapshot_age = std::chrono::seconds(3);
  };

  static constexpr std::size_t kMaxRequestHeader = 8 * 1024;

  /// Binds and starts serving. Throws rsg::EnvironmentError when the address cannot be bound.
  MetricsServer(const Options& options, MetricsSnapshot first);
  /// Listens on `listen` as the constructor does, and closes it again (--check-config).
  /// @throws rsg::EnvironmentError with the constructor's message when it cannot.
  static void check_can_listen(const transport::Endpoint& listen);
  ~MetricsServer();
  MetricsServer(const MetricsServer&) = delete;
  MetricsServer& operator=(const MetricsServer&) = delete;

  /// Makes `snapshot` what the next scrape reports. Any thread; never waits for a client.
  void publish(MetricsSnapshot snapshot);

  std::uint16_t port() const;

  /// The metric families the server adds to format_metrics' (metrics.hpp).
  static std::vector<std::string> family_names();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace rsg::gateway
