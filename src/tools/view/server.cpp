#include "server.hpp"

#include <pthread.h>
#include <spdlog/spdlog.h>

#include <atomic>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <chrono>
#include <deque>
#include <future>
#include <map>
#include <optional>
#include <set>
#include <stdexcept>
#include <thread>
#include <variant>

#include "http_reply.hpp"
#include "rsg/error.hpp"
#include "tcp_listener.hpp"

namespace rsg::tools::view {
namespace {

namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
namespace net = boost::asio;
using tcp = net::ip::tcp;
using foxglove::Level;

// A client whose control messages (statuses, errors) pile up this high never reads: it is closed.
constexpr std::size_t kMaxControlBacklog = 1024;
constexpr auto kDropReportPeriod = std::chrono::seconds(1);
constexpr std::size_t kMaxRequestHeader = 8 * 1024;
constexpr auto kHttpTimeout = std::chrono::seconds(30);

std::string endpoint_text(const tcp::socket& socket) {
  boost::system::error_code ec;
  const auto remote = socket.remote_endpoint(ec);
  return ec ? std::string("?") : remote.address().to_string() + ":" + std::to_string(remote.port());
}

class WsSession;

/// What the I/O thread shares between connections. Touched only from the I/O thread, except the atomics.
struct Hub {
  ServerOptions options;
  std::vector<foxglove::Channel> channels;
  std::string advertise;
  std::map<std::string, WebFile, std::less<>> files;
  std::set<std::shared_ptr<WsSession>> sessions;
  std::uint64_t next_session = 1;
  std::atomic<std::uint64_t> dropped{0};
  // Per channel, in the order of `channels`; published is written by publish()'s caller.
  std::unique_ptr<std::atomic<std::uint64_t>[]> channel_published, channel_dropped;

  /// The index of channel `id` in `channels`, or nothing.
  std::optional<std::size_t> find(std::uint32_t id) const {
    for (std::size_t i = 0; i < channels.size(); ++i)
      if (channels[i].id == id) return i;
    return std::nullopt;
  }
  bool has_channel(std::uint32_t id) const { return find(id).has_value(); }
};

class WsSession : public std::enable_shared_from_this<WsSession> {
 public:
  WsSession(beast::tcp_stream&& stream, Hub& hub, std::string_view subprotocol)
      : ws_(std::move(stream)),
        hub_(hub),
        subprotocol_(subprotocol),
        peer_(endpoint_text(beast::get_lowest_layer(ws_).socket())),
        timer_(ws_.get_executor()) {}

  void accept(http::request<http::string_body> request) {
    beast::get_lowest_layer(ws_).expires_never();
    ws_.set_option(websocket::stream_base::timeout::suggested(beast::role_type::server));
    ws_.set_option(
        websocket::stream_base::decorator([protocol = subprotocol_](websocket::response_type& response) {
          response.set(http::field::sec_websocket_protocol, protocol);
          response.set(http::field::server, "rsg_view");
        }));
    ws_.read_message_max(hub_.options.max_client_message);
    ws_.async_accept(request, [self = shared_from_this()](beast::error_code ec) { self->on_accept(ec); });
  }

  /// A sample for `channel`: queued for each subscription of it, the oldest dropped when full.
  void deliver(std::uint32_t channel, std::uint64_t time_ns, const Payload& payload) {
    for (auto& [id, subscription] : subscriptions_) {
      if (subscription.channel != channel) continue;
      if (subscription.queue.size() >= hub_.options.queue_depth) {
        subscription.queue.pop_front();
        ++dropped_;
        ++dropped_by_channel_[channel];
        hub_.dropped.fetch_add(1, std::memory_order_relaxed);
        if (const auto index = hub_.find(channel))
          hub_.channel_dropped[*index].fetch_add(1, std::memory_order_relaxed);
      }
      subscription.queue.push_back({time_ns, payload});
    }
    pump();
  }

  void close() {
    if (closed_) return;
    closed_ = true;
    timer_.cancel();
    beast::error_code ignored;
    beast::get_lowest_layer(ws_).socket().shutdown(tcp::socket::shutdown_both, ignored);
    beast::get_lowest_layer(ws_).close();
  }

 private:
  struct Queued {
    std::uint64_t time_ns;
    Payload payload;
  };
  struct Subscription {
    std::uint32_t channel;
    std::deque<Queued> queue;
  };

  void on_accept(beast::error_code ec) {
    if (ec) return;  // never counted as a client
    if (hub_.sessions.size() >= hub_.options.max_clients) {
      spdlog::warn("refusing {}: already {} clients", peer_, hub_.sessions.size());
      ws_.async_close(websocket::close_reason(websocket::close_code::try_again_later, "too many clients"),
                      [self = shared_from_this()](beast::error_code) {});
      return;
    }
    hub_.sessions.insert(shared_from_this());
    spdlog::info("client {} connected ({})", peer_, subprotocol_);
    send_text(foxglove::server_info("rsg_view", std::to_string(hub_.next_session++)));
    send_text(hub_.advertise);
    read();
    schedule_drop_report();
  }

  void read() {
    ws_.async_read(in_,
                   [self = shared_from_this()](beast::error_code ec, std::size_t) { self->on_read(ec); });
  }

  void on_read(beast::error_code ec) {
    if (ec) {
      if (ec == websocket::error::message_too_big)
        spdlog::warn("client {} sent a message over {} bytes: closed", peer_,
                     hub_.options.max_client_message);
      return finish();
    }
    const auto now = std::chrono::steady_clock::now();
    if (now - window_start_ >= std::chrono::seconds(1)) {
      window_start_ = now;
      window_count_ = 0;
    }
    if (++window_count_ > hub_.options.max_client_messages_per_s) {
      if (window_count_ == hub_.options.max_client_messages_per_s + 1)
        send_text(
            foxglove::status(Level::error, "too many messages per second: ignoring the rest of this second"));
    } else if (!ws_.got_text()) {
      send_text(foxglove::status(Level::error, "binary client messages (publishing) are not supported"));
    } else {
      handle(beast::buffers_to_string(in_.data()));
    }
    in_.consume(in_.size());
    read();
  }

  void handle(const std::string& text) {
    std::visit(
        [this](auto&& message) {
          using T = std::decay_t<decltype(message)>;
          if constexpr (std::is_same_v<T, foxglove::Subscribe>) {
            for (const auto& subscription : message.subscriptions) {
              if (!hub_.has_channel(subscription.channel_id)) {
                send_text(
                    foxglove::status(Level::error, "no channel " + std::to_string(subscription.channel_id)));
              } else if (subscriptions_.contains(subscription.id)) {
                send_text(foxglove::status(
                    Level::error, "subscription id " + std::to_string(subscription.id) + " is in use"));
              } else {
                subscriptions_[subscription.id] = Subscription{subscription.channel_id, {}};
              }
            }
          } else if constexpr (std::is_same_v<T, foxglove::Unsubscribe>) {
            for (const auto id : message.subscription_ids) subscriptions_.erase(id);
          } else if constexpr (std::is_same_v<T, foxglove::Unsupported>) {
            send_text(foxglove::status(Level::error, "unsupported operation '" + message.op + "'"));
          } else {
            spdlog::warn("client {}: malformed message: {}", peer_, message.reason);
            send_text(foxglove::status(Level::error, "malformed message: " + message.reason));
          }
        },
        foxglove::parse_client_message(text));
  }

  void send_text(std::string text) {
    if (control_.size() >= kMaxControlBacklog) {
      spdlog::warn("client {} reads none of its status messages: closed", peer_);
      return finish();
    }
    control_.push_back(std::move(text));
    pump();
  }

  /// Starts the next write: control messages first, then one message of each subscription in turn.
  void pump() {
    if (writing_ || closed_) return;
    if (!control_.empty()) {
      text_out_ = std::move(control_.front());
      control_.pop_front();
      writing_ = true;
      ws_.text(true);
      ws_.async_write(net::buffer(text_out_),
                      [self = shared_from_this()](beast::error_code ec, std::size_t) { self->on_write(ec); });
      return;
    }
    if (subscriptions_.empty()) return;
    auto it = subscriptions_.upper_bound(last_served_);
    for (std::size_t tried = 0; tried < subscriptions_.size(); ++tried, ++it) {
      if (it == subscriptions_.end()) it = subscriptions_.begin();
      if (it->second.queue.empty()) continue;
      last_served_ = it->first;
      Queued next = std::move(it->second.queue.front());
      it->second.queue.pop_front();
      header_out_ = foxglove::message_header(it->first, next.time_ns);
      payload_out_ = std::move(next.payload);
      const std::array<net::const_buffer, 2> buffers{net::buffer(header_out_), net::buffer(*payload_out_)};
      writing_ = true;
      ws_.binary(true);
      ws_.async_write(buffers,
                      [self = shared_from_this()](beast::error_code ec, std::size_t) { self->on_write(ec); });
      return;
    }
  }

  void on_write(beast::error_code ec) {
    writing_ = false;
    payload_out_.reset();
    if (ec) return finish();
    pump();
  }

  void schedule_drop_report() {
    timer_.expires_after(kDropReportPeriod);
    timer_.async_wait([self = shared_from_this()](beast::error_code ec) {
      if (ec || self->closed_) return;
      if (self->dropped_ != self->reported_) {
        self->reported_ = self->dropped_;
        const std::string text = "dropped " + std::to_string(self->dropped_) +
                                 " messages: this connection reads slower than the data arrives (" +
                                 self->drops_by_topic() + ")";
        spdlog::warn("client {}: {}", self->peer_, text);
        self->send_text(foxglove::status(Level::warning, text, "rsg_view.dropped"));
      }
      self->schedule_drop_report();
    });
  }

  /// "topic (schema): n, ..." for each channel that lost messages.
  std::string drops_by_topic() const {
    std::string text;
    for (const auto& [channel, count] : dropped_by_channel_) {
      const auto index = hub_.find(channel);
      if (!index) continue;
      const auto& c = hub_.channels[*index];
      text += (text.empty() ? "" : ", ") + c.topic + " (" + c.schema_name + "): " + std::to_string(count);
    }
    return text;
  }

  void finish() {
    if (hub_.sessions.erase(shared_from_this()) != 0)
      spdlog::info("client {} disconnected (dropped {} messages)", peer_, dropped_);
    close();
  }

  websocket::stream<beast::tcp_stream> ws_;
  Hub& hub_;
  std::string subprotocol_;
  std::string peer_;
  net::steady_timer timer_;
  beast::flat_buffer in_;
  std::deque<std::string> control_;
  std::map<std::uint32_t, Subscription> subscriptions_;
  std::uint32_t last_served_ = 0;
  std::string text_out_;
  std::array<std::uint8_t, foxglove::kMessageHeaderSize> header_out_{};
  Payload payload_out_;
  bool writing_ = false;
  bool closed_ = false;
  std::uint64_t dropped_ = 0, reported_ = 0;
  std::map<std::uint32_t, std::uint64_t> dropped_by_channel_;  // channel id -> messages
  std::chrono::steady_clock::time_point window_start_{};
  std::size_t window_count_ = 0;
};

/// One HTTP connection: serves files until it asks for a WebSocket, then hands its socket over.
class HttpSession : public std::enable_shared_from_this<HttpSession> {
 public:
  HttpSession(tcp::socket&& socket, Hub& hub) : stream_(std::move(socket)), hub_(hub) {}

  void read() {
    parser_.emplace();
    parser_->header_limit(kMaxRequestHeader);
    parser_->body_limit(hub_.options.max_client_message);
    stream_.expires_after(kHttpTimeout);
    http::async_read(stream_, buffer_, *parser_,
                     [self = shared_from_this()](beast::error_code ec, std::size_t) { self->on_read(ec); });
  }

 private:
  void on_read(beast::error_code ec) {
    if (ec) {
      beast::error_code ignored;
      stream_.socket().shutdown(tcp::socket::shutdown_both, ignored);
      return;
    }
    auto request = parser_->release();
    if (websocket::is_upgrade(request)) {
      const auto offered = request[http::field::sec_websocket_protocol];
      const auto subprotocol = foxglove::choose_subprotocol({offered.data(), offered.size()});
      if (subprotocol.empty())
        return respond(request, http::status::bad_request, "text/plain",
                       "rsg_view speaks the Foxglove WebSocket protocol: offer the subprotocol " +
                           std::string(foxglove::kSdkSubprotocol) + " or " +
                           std::string(foxglove::kLegacySubprotocol) + "\n");
      std::make_shared<WsSession>(std::move(stream_), hub_, subprotocol)->accept(std::move(request));
      return;
    }
    if (request.method() != http::verb::get && request.method() != http::verb::head)
      return respond(request, http::status::method_not_allowed, "text/plain", "GET only\n");
    const auto raw_target = request.target();
    std::string_view target(raw_target.data(), raw_target.size());
    target = target.substr(0, target.find('?'));
    const auto file = hub_.files.find(target);
    if (file == hub_.files.end())
      return respond(request, http::status::not_found, "text/plain", "not found\n");
    respond(request, http::status::ok, file->second.content_type, file->second.body);
  }

  void respond(const http::request<http::string_body>& request, http::status status, std::string_view type,
               std::string body) {
    if (request.method() == http::verb::head) body.clear();
    app::write_http_reply(shared_from_this(), stream_, "rsg_view", request.version(), request.keep_alive(),
                          {status, type, std::move(body)});
  }

  beast::tcp_stream stream_;
  Hub& hub_;
  beast::flat_buffer buffer_;
  std::optional<http::request_parser<http::string_body>> parser_;
};

}  // namespace

struct Server::Impl {
  net::io_context io{1};
  Hub hub;
  tcp::acceptor acceptor{io};
  std::thread thread;

  void accept() {
    acceptor.async_accept([this](beast::error_code ec, tcp::socket socket) {
      if (ec == net::error::operation_aborted) return;
      if (!ec) std::make_shared<HttpSession>(std::move(socket), hub)->read();
      accept();
    });
  }
};

Server::Server(const ServerOptions& options, std::vector<foxglove::Channel> channels,
               std::vector<WebFile> files)
    : impl_(std::make_unique<Impl>()) {
  impl_->hub.options = options;
  impl_->hub.advertise = foxglove::advertise(channels);
  impl_->hub.channels = std::move(channels);
  const std::size_t count = impl_->hub.channels.size();
  impl_->hub.channel_published = std::make_unique<std::atomic<std::uint64_t>[]>(count);
  impl_->hub.channel_dropped = std::make_unique<std::atomic<std::uint64_t>[]>(count);
  for (auto& file : files) {
    std::string path = file.path;
    impl_->hub.files.emplace(std::move(path), std::move(file));
  }
  beast::error_code ec;
  const auto address = net::ip::make_address(options.host, ec);
  if (ec) throw InputError("--listen: '" + options.host + "' is no IP address");
  if (const auto listen_error = rsg::app::listen_on(impl_->acceptor, tcp::endpoint(address, options.port)))
    throw EnvironmentError("cannot listen on " + options.host + ":" + std::to_string(options.port) + ": " +
                           listen_error.message());
  impl_->accept();
  impl_->thread = std::thread([impl = impl_.get()] {
    ::pthread_setname_np(::pthread_self(), "rsg-view-http");  // CONTRIBUTING.md, Threads
    impl->io.run();
  });
}

Server::~Server() {
  // Closed on the I/O thread, which owns the sessions; stopping the loop before this ran would leak them.
  std::promise<void> closed;
  net::post(impl_->io, [impl = impl_.get(), &closed] {
    beast::error_code ignored;
    impl->acceptor.close(ignored);
    for (const auto& session : std::set(impl->hub.sessions)) session->close();
    impl->hub.sessions.clear();
    closed.set_value();
  });
  closed.get_future().wait();
  impl_->io.stop();
  impl_->thread.join();
}

void Server::publish(std::uint32_t channel, std::uint64_t time_ns, Payload payload) {
  if (const auto index = impl_->hub.find(channel))
    impl_->hub.channel_published[*index].fetch_add(1, std::memory_order_relaxed);
  net::post(impl_->io, [hub = &impl_->hub, channel, time_ns, payload = std::move(payload)] {
    for (const auto& session : hub->sessions) session->deliver(channel, time_ns, payload);
  });
}

std::uint16_t Server::port() const { return impl_->acceptor.local_endpoint().port(); }

std::uint64_t Server::dropped() const { return impl_->hub.dropped.load(std::memory_order_relaxed); }

std::vector<ChannelCount> Server::channel_counts() const {
  const Hub& hub = impl_->hub;
  std::vector<ChannelCount> counts;
  for (std::size_t i = 0; i < hub.channels.size(); ++i)
    counts.push_back({hub.channels[i].id, hub.channel_published[i].load(std::memory_order_relaxed),
                      hub.channel_dropped[i].load(std::memory_order_relaxed)});
  return counts;
}

}  // namespace rsg::tools::view
