#include "tools/view/server.hpp"

#include <malloc.h>
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

#include "app/http_reply.hpp"
#include "app/repeated_log.hpp"
#include "app/tcp_listener.hpp"
#include "rsg/error.hpp"

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
constexpr std::size_t kMaxRequestHeader = 8 * 1024;
constexpr auto kTickPeriod = std::chrono::seconds(1);
// A client that queued more than this gives its memory back to the system when it leaves (glibc
// keeps freed small blocks otherwise, and the process stays that large).
constexpr std::size_t kTrimAfter = 1 << 20;
using SteadyClock = std::chrono::steady_clock;

std::string endpoint_text(const tcp::socket& socket) {
  boost::system::error_code ec;
  const auto remote = socket.remote_endpoint(ec);
  return ec ? std::string("?") : remote.address().to_string() + ":" + std::to_string(remote.port());
}

net::ip::address address_of(const tcp::socket& socket) {
  boost::system::error_code ec;
  const auto remote = socket.remote_endpoint(ec);
  return ec ? net::ip::address() : remote.address();
}

class WsSession;

/// What the I/O thread shares between connections. Touched only from the I/O thread, except the atomics.
struct Hub {
  explicit Hub(const ServerOptions& options)
      : options(options), table({options.max_connections, options.max_connections_per_address}) {}

  ServerOptions options;
  std::vector<foxglove::Channel> channels;
  std::string advertise;
  std::map<std::string, WebFile, std::less<>> files;
  std::set<std::shared_ptr<WsSession>> sessions;
  std::uint64_t next_session = 1;
  app::ConnectionTable table;
  std::array<std::atomic<std::uint64_t>, Server::kLimitNames.size()> limits{};
  std::array<app::RepeatedLog, Server::kLimitNames.size()> limit_logs{};
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

  /// Counts a limit that bit, and says so the first time and then at most once a minute.
  void count(LimitEvent event, std::string_view what, std::uint64_t n = 1) {
    const auto i = static_cast<std::size_t>(event);
    const auto total = limits[i].fetch_add(n, std::memory_order_relaxed) + n;
    if (limit_logs[i].take(SteadyClock::now(), n) > 0)
      spdlog::warn("limit {}: {} ({} so far)", Server::kLimitNames[i], what, total);
  }

  /// How long a client has to subscribe before it may make room for another.
  SteadyClock::duration subscribe_grace() const {
    return std::min<SteadyClock::duration>(Server::kSubscribeGrace, options.idle_timeout / 2);
  }
};

class WsSession : public std::enable_shared_from_this<WsSession>, public app::ConnectionTable::Member {
 public:
  WsSession(beast::tcp_stream&& stream, Hub& hub, std::string_view subprotocol)
      : ws_(std::move(stream)),
        hub_(hub),
        subprotocol_(subprotocol),
        peer_(endpoint_text(beast::get_lowest_layer(ws_).socket())),
        address_(address_of(beast::get_lowest_layer(ws_).socket())),
        timer_(ws_.get_executor()) {
    slot_.join(hub_.table, address_, *this);
  }
  ~WsSession() {
    if (buffered_peak_ > kTrimAfter) ::malloc_trim(0);
  }
  WsSession(const WsSession&) = delete;
  WsSession& operator=(const WsSession&) = delete;

  void accept(http::request<http::string_body> request) {
    beast::get_lowest_layer(ws_).expires_never();
    websocket::stream_base::timeout timeout{};
    timeout.handshake_timeout = hub_.options.handshake_timeout;
    timeout.idle_timeout = hub_.options.idle_timeout;  // a ping at half of it; no answer closes
    timeout.keep_alive_pings = true;
    ws_.set_option(timeout);
    ws_.set_option(
        websocket::stream_base::decorator([protocol = subprotocol_](websocket::response_type& response) {
          response.set(http::field::sec_websocket_protocol, protocol);
          response.set(http::field::server, "rsg_view");
        }));
    ws_.read_message_max(hub_.options.max_client_message);
    ws_.async_accept(request, [self = shared_from_this()](beast::error_code ec) { self->on_accept(ec); });
  }

  /// A sample for `channel`: queued for each subscription of it, the oldest dropped when full.
  /// A client over its byte budget is closed (the caller iterates the sessions: finish() follows
  /// from the read that fails).
  void deliver(std::uint32_t channel, std::uint64_t time_ns, const Payload& payload) {
    if (closed_) return;
    for (auto& [id, subscription] : subscriptions_) {
      if (subscription.channel != channel) continue;
      if (subscription.queue.size() >= hub_.options.queue_depth) {
        buffered_ -= queued_size(subscription.queue.front());
        subscription.queue.pop_front();
        ++dropped_;
        ++dropped_by_channel_[channel];
        hub_.dropped.fetch_add(1, std::memory_order_relaxed);
        if (const auto index = hub_.find(channel))
          hub_.channel_dropped[*index].fetch_add(1, std::memory_order_relaxed);
      }
      subscription.queue.push_back({time_ns, payload});
      buffered_ += queued_size(subscription.queue.back());
    }
    if (over_budget()) return close();
    pump();
  }

  void close() {
    if (closed_) return;
    closed_ = true;
    slot_.leave();
    timer_.cancel();
    // Its queues go now: a closed client holds no payloads until its last operation returns.
    subscriptions_.clear();
    control_.clear();
    buffered_ = 0;
    beast::error_code ignored;
    beast::get_lowest_layer(ws_).socket().shutdown(tcp::socket::shutdown_both, ignored);
    beast::get_lowest_layer(ws_).close();
  }

  void evict() override { finish(); }

  /// Without a subscription for longer than its grace (Hub::subscribe_grace), whatever it sent:
  /// may make room for another client.
  bool idle() const { return idle_; }
  std::uint64_t number() const { return number_; }
  const net::ip::address& address() const { return address_; }

 private:
  struct Queued {
    std::uint64_t time_ns;
    Payload payload;
  };
  struct Subscription {
    std::uint32_t channel;
    std::deque<Queued> queue;
  };

  static std::size_t queued_size(const Queued& queued) {
    return queued.payload->size() + foxglove::kMessageHeaderSize;
  }

  bool over_budget() {
    buffered_peak_ = std::max(buffered_peak_, buffered_);
    if (buffered_ <= hub_.options.max_client_buffer) return false;
    hub_.count(LimitEvent::kBuffer, "client " + peer_ + " has over " +
                                        std::to_string(hub_.options.max_client_buffer) +
                                        " bytes queued: closed");
    return true;
  }

  void on_accept(beast::error_code ec) {
    if (ec) {  // never counted as a client
      if (ec == beast::error::timeout)
        hub_.count(LimitEvent::kHandshake, "client " + peer_ + " did not finish its WebSocket handshake");
      return close();
    }
    if (!admit()) {
      slot_.leave();
      ws_.async_close(websocket::close_reason(websocket::close_code::try_again_later, "too many clients"),
                      [self = shared_from_this()](beast::error_code) {});
      return;
    }
    hub_.sessions.insert(shared_from_this());
    number_ = hub_.next_session++;
    connected_ = unsubscribed_since_ = SteadyClock::now();
    spdlog::info("client {} connected ({})", peer_, subprotocol_);
    send_text(foxglove::server_info("rsg_view", std::to_string(number_)));
    send_text(hub_.advertise);
    read();
    schedule_tick();
  }

  /// Room for this client: under both caps, or an idle client of the address holding the most
  /// clients closed to make it, the oldest of them. A client that subscribed, or is within its
  /// grace, is never closed for another; with none idle this one is refused (false). A client of
  /// an address at its cap is refused, and an address that holds clients already takes a place of
  /// another address only from one holding at least two more: an attacker renewing its clients
  /// would otherwise close its own or another address's idle ones in turn for ever, every renewed
  /// one within a fresh grace, so that none would ever be idle for a newcomer.
  bool admit() {
    std::map<net::ip::address, std::size_t> held;
    for (const auto& session : hub_.sessions) ++held[session->address()];
    const std::size_t mine = held[address_];
    if (mine >= hub_.options.max_clients_per_address) {
      hub_.count(LimitEvent::kClientsPerAddress, "already " + std::to_string(mine) + " clients from " +
                                                     address_.to_string() + ": refused " + peer_);
      return false;
    }
    if (hub_.sessions.size() < hub_.options.max_clients) return true;
    std::shared_ptr<WsSession> victim;
    for (const auto& session : hub_.sessions) {
      if (!session->idle() || (mine > 0 && held[session->address()] < mine + 2)) continue;
      if (!victim || held[session->address()] > held[victim->address()] ||
          (held[session->address()] == held[victim->address()] && session->number() < victim->number()))
        victim = session;
    }
    hub_.count(LimitEvent::kClients,
               "already " + std::to_string(hub_.sessions.size()) + " clients: " +
                   (victim ? "closed an idle one of " + victim->address().to_string() : "refused " + peer_));
    if (!victim) return false;
    victim->finish();
    return true;
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
      if (ec == beast::error::timeout)
        hub_.count(LimitEvent::kIdle, "client " + peer_ + " answered no ping: closed");
      return finish();
    }
    // What a client sends never makes it less idle: only a subscription does (schedule_tick).
    const auto now = SteadyClock::now();
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
            // One status for the whole message however many it refuses: a message of thousands of
            // bad subscriptions must not become thousands of statuses.
            std::string first_error;
            std::size_t errors = 0, over_limit = 0;
            for (const auto& subscription : message.subscriptions) {
              std::string error;
              if (!hub_.has_channel(subscription.channel_id)) {
                error = "no channel " + std::to_string(subscription.channel_id);
              } else if (subscriptions_.contains(subscription.id)) {
                error = "subscription id " + std::to_string(subscription.id) + " is in use";
              } else if (subscriptions_.size() >= hub_.options.max_subscriptions) {
                error =
                    "at most " + std::to_string(hub_.options.max_subscriptions) + " subscriptions per client";
                ++over_limit;
              } else {
                subscriptions_[subscription.id] = Subscription{subscription.channel_id, {}};
              }
              if (!error.empty() && errors++ == 0) first_error = std::move(error);
            }
            if (errors > 0)
              send_text(foxglove::status(
                  Level::error,
                  first_error +
                      (errors > 1 ? " (and " + std::to_string(errors - 1) + " more refused)" : "")));
            if (over_limit > 0)
              hub_.count(LimitEvent::kSubscriptions,
                         "client " + peer_ + ": " + std::to_string(over_limit) + " subscription(s) refused",
                         over_limit);
          } else if constexpr (std::is_same_v<T, foxglove::Unsubscribe>) {
            for (const auto id : message.subscription_ids) {
              const auto it = subscriptions_.find(id);
              if (it == subscriptions_.end()) continue;
              for (const auto& queued : it->second.queue) buffered_ -= queued_size(queued);
              subscriptions_.erase(it);
              if (subscriptions_.empty()) unsubscribed_since_ = SteadyClock::now();
            }
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
    if (closed_) return;
    if (control_.size() >= kMaxControlBacklog) {
      spdlog::warn("client {} reads none of its status messages: closed", peer_);
      return finish();
    }
    buffered_ += text.size();
    control_.push_back(std::move(text));
    if (over_budget()) return finish();
    pump();
  }

  /// Starts the next write: control messages first, then one message of each subscription in turn.
  void pump() {
    if (writing_ || closed_) return;
    if (!control_.empty()) {
      text_out_ = std::move(control_.front());
      control_.pop_front();
      buffered_ -= text_out_.size();
      writing_ = true;
      write_started_ = SteadyClock::now();
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
      buffered_ -= queued_size(next);
      write_started_ = SteadyClock::now();
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

  /// Once a second: the drop report, and the idle and stall limits.
  void schedule_tick() {
    timer_.expires_after(kTickPeriod);
    timer_.async_wait([self = shared_from_this()](beast::error_code ec) {
      if (ec || self->closed_) return;
      const auto now = SteadyClock::now();
      const auto unsubscribed = now - self->unsubscribed_since_;
      // The grace runs once, from connecting: unsubscribing and subscribing again buys no more.
      self->idle_ = self->subscriptions_.empty() && now - self->connected_ >= self->hub_.subscribe_grace();
      self->slot_.waiting(self->idle_);
      if (self->idle_ && unsubscribed >= self->hub_.options.idle_timeout) {
        self->hub_.count(LimitEvent::kIdle, "client " + self->peer_ + " subscribed to nothing: closed");
        return self->finish();
      }
      if (self->writing_ && now - self->write_started_ >= self->hub_.options.stall_timeout) {
        self->hub_.count(LimitEvent::kStalled,
                         "client " + self->peer_ + " takes none of its messages: closed");
        return self->finish();
      }
      if (self->dropped_ != self->reported_) {
        self->reported_ = self->dropped_;
        const std::string text = "dropped " + std::to_string(self->dropped_) +
                                 " messages: this connection reads slower than the data arrives (" +
                                 self->drops_by_topic() + ")";
        spdlog::warn("client {}: {}", self->peer_, text);
        self->send_text(foxglove::status(Level::warning, text, "rsg_view.dropped"));
      }
      self->schedule_tick();
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
  net::ip::address address_;
  net::steady_timer timer_;
  app::ConnectionTable::Slot slot_;
  std::uint64_t number_ = 0;
  // Since when it has had no subscription (connected, or unsubscribed from its last one).
  SteadyClock::time_point unsubscribed_since_ = SteadyClock::now(), write_started_{};
  SteadyClock::time_point connected_ = SteadyClock::now();
  bool idle_ = false;
  std::size_t buffered_ = 0, buffered_peak_ = 0;  // bytes queued: payloads, their headers, statuses
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
  SteadyClock::time_point window_start_{};
  std::size_t window_count_ = 0;
};

/// One HTTP connection: serves files until it asks for a WebSocket, then hands its socket over.
class HttpSession : public std::enable_shared_from_this<HttpSession>, public app::ConnectionTable::Member {
 public:
  HttpSession(tcp::socket&& socket, Hub& hub, const net::ip::address& address)
      : stream_(std::move(socket)), hub_(hub) {
    slot_.join(hub_.table, address, *this);
  }
  HttpSession(const HttpSession&) = delete;
  HttpSession& operator=(const HttpSession&) = delete;

  void read() {
    parser_.emplace();
    parser_->header_limit(kMaxRequestHeader);
    parser_->body_limit(hub_.options.max_client_message);
    stream_.expires_after(hub_.options.handshake_timeout);
    slot_.waiting(true);
    http::async_read(stream_, buffer_, *parser_,
                     [self = shared_from_this()](beast::error_code ec, std::size_t) { self->on_read(ec); });
  }

  void evict() override {
    beast::error_code ignored;
    stream_.socket().shutdown(tcp::socket::shutdown_both, ignored);
    stream_.socket().close(ignored);
  }

 private:
  void on_read(beast::error_code ec) {
    slot_.waiting(false);
    if (ec) {
      if (ec == beast::error::timeout)
        hub_.count(LimitEvent::kHandshake, "a connection sent no whole request in time: closed");
      slot_.leave();
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
      slot_.leave();  // the WebSocket session takes the connection's place
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
  app::ConnectionTable::Slot slot_;
  beast::flat_buffer buffer_;
  std::optional<http::request_parser<http::string_body>> parser_;
};

}  // namespace

struct Server::Impl {
  explicit Impl(const ServerOptions& options) : hub(options) {}

  Hub hub;  // first: the sessions the context destroys last still leave its table
  net::io_context io{1};
  tcp::acceptor acceptor{io};
  app::AcceptLoop accepting{acceptor, "rsg_view",
                            [this](tcp::socket socket) { on_connection(std::move(socket)); },
                            [this] {
                              hub.count(LimitEvent::kAcceptFailures, "accept failed: backing off");
                              hub.table.evict_oldest_waiting();
                            }};
  std::jthread thread;  // named rsg-view-http

  void on_connection(tcp::socket socket) {
    beast::error_code ec;
    const auto remote = socket.remote_endpoint(ec);
    if (ec) return;  // gone already
    const auto admission = hub.table.make_room(remote.address());
    if (admission.limit) {
      const bool per_address = *admission.limit == app::ConnectionLimit::kPerAddress;
      hub.count(per_address ? LimitEvent::kPerAddress : LimitEvent::kConnections,
                std::string(admission.admitted ? "closed an older waiting connection for "
                                               : "refused a connection from ") +
                    remote.address().to_string() +
                    (per_address ? " (per address)" : " (" + std::to_string(hub.table.size()) + " open)"));
    }
    if (!admission.admitted) {
      socket.close(ec);
      return;
    }
    std::make_shared<HttpSession>(std::move(socket), hub, remote.address())->read();
  }
};

Server::Server(const ServerOptions& options, std::vector<foxglove::Channel> channels,
               std::vector<WebFile> files)
    : impl_(std::make_unique<Impl>(options)) {
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
  impl_->accepting.start();
  impl_->thread = std::jthread([impl = impl_.get()] {
    ::pthread_setname_np(::pthread_self(), "rsg-view-http");  // CONTRIBUTING.md, Threads
    impl->io.run();
  });
}

Server::~Server() {
  // Closed on the I/O thread, which owns the sessions; stopping the loop before this ran would leak them.
  std::promise<void> closed;
  net::post(impl_->io, [impl = impl_.get(), &closed] {
    impl->accepting.stop();
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

std::array<std::uint64_t, Server::kLimitNames.size()> Server::limit_counts() const {
  std::array<std::uint64_t, kLimitNames.size()> counts{};
  for (std::size_t i = 0; i < counts.size(); ++i)
    counts[i] = impl_->hub.limits[i].load(std::memory_order_relaxed);
  return counts;
}

std::vector<ChannelCount> Server::channel_counts() const {
  const Hub& hub = impl_->hub;
  std::vector<ChannelCount> counts;
  for (std::size_t i = 0; i < hub.channels.size(); ++i)
    counts.push_back({hub.channels[i].id, hub.channel_published[i].load(std::memory_order_relaxed),
                      hub.channel_dropped[i].load(std::memory_order_relaxed)});
  return counts;
}

}  // namespace rsg::tools::view
