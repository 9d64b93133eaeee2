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
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "foxglove_protocol.hpp"

namespace rsg::tools::view {

struct ServerOptions {
  std::string host = "127.0.0.1";
  std::uint16_t port = 8765;  ///< 0: any free port (see Server::port())
  std::size_t max_clients = 16;
  std::size_t queue_depth = 256;                ///< messages per subscription and client
  std::size_t max_client_message = 64 * 1024;   ///< bytes of one client text frame
  std::size_t max_client_messages_per_s = 100;  ///< more are answered with an error and ignored
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

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace rsg::tools::view
