// rsg_view's server: one TCP port, Boost.Beast underneath, that answers plain HTTP requests with
// the page's files and WebSocket upgrades with the Foxglove WebSocket protocol.
//
// One I/O thread runs every connection. `publish` may be called from any thread (the DDS reader's)
// and never blocks: it hands the payload over and returns. Each client has a bounded queue per
// subscription; when a client reads slower than data arrives its oldest messages are dropped, the
// drops are counted (per channel), logged and reported to that client as a status message.
// Subscriptions are served round-robin, one message each in turn, so a small channel (status,
// transform) gets at least the share of a big one and, arriving slower than that share, loses
// nothing however far behind the client is on the big one (view.fair_share tests it).
//
// What an outsider can make it hold is bounded (docs/security.md; view.attack_* test it):
// connections in total and per address (app::ConnectionTable: at a limit the oldest connection
// that only waits makes room, an HTTP one waiting for its request or a WebSocket client with no
// subscription past its grace), WebSocket clients in total and per address (at a limit an idle
// client makes room, from the address holding the most; one that subscribed, or is still within
// kSubscribeGrace of connecting, never does), subscriptions per client, bytes queued per client (a client
// over it is closed, not slowed for everyone), the time to send a request or handshake, the time a
// client may sit without a subscription, the time a write to it may stay pending; at the fd limit
// the accept loop backs off and closes the oldest waiting connection. Each limit that bites is
// counted (limit_counts(), logged at exit) and logged at most once a minute.
#pragma once

#include <array>
#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "foxglove/foxglove_protocol.hpp"

namespace rsg::tools::view {

struct ServerOptions {
  std::string host = "127.0.0.1";
  std::uint16_t port = 8765;                    ///< 0: any free port (see Server::port())
  std::size_t max_clients = 16;                 ///< WebSocket clients
  std::size_t max_clients_per_address = 4;      ///< the same per client IP address
  std::size_t max_connections = 64;             ///< TCP connections, HTTP and WebSocket
  std::size_t max_connections_per_address = 8;  ///< the same per client IP address
  std::size_t max_subscriptions = 16;  ///< per client (Foxglove takes one per channel); more are refused
  std::size_t max_client_buffer = 32 << 20;     ///< bytes queued for one client; over it it is closed
  std::size_t queue_depth = 256;                ///< messages per subscription and client
  std::size_t max_client_message = 64 * 1024;   ///< bytes of one client text frame
  std::size_t max_client_messages_per_s = 100;  ///< more are answered with an error and ignored
  /// An HTTP request (a WebSocket upgrade too) and the WebSocket handshake must arrive within this.
  std::chrono::milliseconds handshake_timeout = std::chrono::seconds(10);
  /// A WebSocket client without a subscription, or answering no ping, is closed after this; what it
  /// sends does not count (a client is idle by what it receives). For half of it (at most
  /// Server::kSubscribeGrace) after connecting or unsubscribing it may not be evicted either.
  std::chrono::milliseconds idle_timeout = std::chrono::seconds(60);
  /// A client that takes none of its messages for this long is closed.
  std::chrono::milliseconds stall_timeout = std::chrono::seconds(20);
};

/// What a limit did, counted since start: the order of Server::kLimitNames.
enum class LimitEvent : std::size_t {
  kPerAddress,         ///< a connection met max_connections_per_address
  kConnections,        ///< a connection met max_connections
  kClients,            ///< a WebSocket client met max_clients
  kClientsPerAddress,  ///< a WebSocket client met max_clients_per_address
  kHandshake,          ///< a request or handshake did not arrive within handshake_timeout
  kIdle,               ///< a client without a subscription (or not answering pings) for idle_timeout
  kStalled,            ///< a client that took nothing for stall_timeout
  kBuffer,             ///< a client over max_client_buffer
  kSubscriptions,      ///< subscriptions refused over max_subscriptions
  kAcceptFailures,     ///< accept failed (EMFILE, ...): backed off
  kCount
};

/// A file the HTTP side serves.
struct WebFile {
  std::string path;  ///< e.g. "/" or "/chart.min.js"
  std::string content_type;
  std::string body;
};

using Payload = std::shared_ptr<const std::vector<std::uint8_t>>;

/// Messages of one channel since start, over all clients.
struct ChannelCount {
  std::uint32_t channel;
  std::uint64_t published;  ///< handed to publish()
  std::uint64_t dropped;    ///< lost by slow clients' queues
};

class Server {
 public:
  /// Binds and starts serving.
  /// @throws rsg::InputError when the host is no IP address, rsg::EnvironmentError when the address
  /// cannot be bound.
  Server(const ServerOptions& options, std::vector<foxglove::Channel> channels, std::vector<WebFile> files);
  ~Server();
  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;

  /// Queues `payload` for every client subscribed to `channel`. Thread-safe, non-blocking.
  void publish(std::uint32_t channel, std::uint64_t time_ns, Payload payload);

  std::uint16_t port() const;
  /// Messages dropped for slow clients, over all clients since start.
  std::uint64_t dropped() const;
  /// The same per channel, in the order of the channels given to the constructor.
  std::vector<ChannelCount> channel_counts() const;

  static constexpr std::array<std::string_view, static_cast<std::size_t>(LimitEvent::kCount)> kLimitNames = {
      "per_address",  "connections", "clients", "clients_per_address", "handshake_timeout",
      "idle_timeout", "stalled",     "buffer",  "subscriptions",       "accept_failures"};

  /// How long a new client has to subscribe before it may make room for another (half of
  /// idle_timeout when that is shorter): a Foxglove client subscribes once it has read the
  /// channels, a person picking topics in a panel takes a few seconds.
  static constexpr std::chrono::seconds kSubscribeGrace{10};
  /// How often each limit bit since start, in the order of kLimitNames.
  std::array<std::uint64_t, kLimitNames.size()> limit_counts() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace rsg::tools::view
