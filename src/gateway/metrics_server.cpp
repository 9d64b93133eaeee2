#include "gateway/metrics_server.hpp"

#include <fmt/format.h>
#include <pthread.h>
#include <spdlog/spdlog.h>

#include <array>
#include <atomic>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/post.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <cstring>
#include <future>
#include <optional>
#include <thread>

#include "app/http_reply.hpp"
#include "app/repeated_log.hpp"
#include "app/tcp_listener.hpp"
#include "rsg/error.hpp"

namespace rsg::gateway {
namespace {

namespace beast = boost::beast;
namespace http = beast::http;
namespace net = boost::asio;
using tcp = net::ip::tcp;

constexpr std::size_t kMaxRequestBody = 1024;  // GET and HEAD carry none
constexpr std::string_view kExpositionType = "text/plain; version=0.0.4; charset=utf-8";

using SnapshotPointer = std::shared_ptr<const MetricsSnapshot>;

/// Why the server closed a connection itself: the `reason` label of rsg_http_connections_closed_total.
enum class Closed : std::size_t { kPerClientLimit, kTotalLimit, kHeaderTimeout, kIdleTimeout, kCount };
constexpr std::array<std::string_view, static_cast<std::size_t>(Closed::kCount)> kClosedReasons = {
    "per_client_limit", "total_limit", "header_timeout", "idle_timeout"};

/// What the I/O thread's connections share. I/O thread only, but for the options and snapshot.
struct Shared {
  explicit Shared(const MetricsServer::Options& options)
      : options(options), table({options.max_connections, options.max_connections_per_client}) {}

  MetricsServer::Options options;
  std::atomic<SnapshotPointer> snapshot;
  app::ConnectionTable table;
  std::array<std::uint64_t, kClosedReasons.size()> closed{};
  std::array<app::RepeatedLog, kClosedReasons.size()> logs{};

  /// Counts a connection the server closed, and says so the first time, then at most once a minute.
  void count(Closed reason) {
    const auto i = static_cast<std::size_t>(reason);
    ++closed[i];
    if (logs[i].take(Clock::now()) > 0)
      spdlog::warn(
          "metrics: {} connection(s) closed so far by {} (limits: {} connections, {} per client, header in "
          "{} "
          "ms, next request within {} ms)",
          closed[i], kClosedReasons[i], options.max_connections, options.max_connections_per_client,
          options.header_timeout.count(), options.idle_timeout.count());
  }
};

/// The server's own families, appended to format_metrics' text with the same labels.
std::string format_server_metrics(const MetricsSnapshot& snapshot, const Shared& shared) {
  std::string labels;
  if (!snapshot.gateway.empty()) labels += "gateway=\"" + escape_label_value(snapshot.gateway) + "\",";
  if (!snapshot.partition.empty()) labels += "partition=\"" + escape_label_value(snapshot.partition) + "\",";
  std::string out =
      "# HELP rsg_http_connections_open Connections open to --metrics\n"
      "# TYPE rsg_http_connections_open gauge\n";
  const std::string common = labels.empty() ? "" : '{' + labels.substr(0, labels.size() - 1) + '}';
  out += fmt::format("rsg_http_connections_open{} {}\n", common, shared.table.size());
  out +=
      "# HELP rsg_http_connections_closed_total Connections to --metrics the server closed by a limit: "
      "per_client_limit, total_limit (an older waiting connection made room, or none could and the new one "
      "was refused), header_timeout, idle_timeout\n"
      "# TYPE rsg_http_connections_closed_total counter\n";
  for (std::size_t i = 0; i < kClosedReasons.size(); ++i)
    out += fmt::format("rsg_http_connections_closed_total{{{}reason=\"{}\"}} {}\n", labels, kClosedReasons[i],
                       shared.closed[i]);
  return out;
}

/// One HTTP connection, alive while a read or write of it is pending.
class Session : public std::enable_shared_from_this<Session>, public app::ConnectionTable::Member {
 public:
  Session(tcp::socket&& socket, Shared& shared, const net::ip::address& address)
      : stream_(std::move(socket)), shared_(shared) {
    slot_.join(shared_.table, address, *this);
  }
  Session(const Session&) = delete;
  Session& operator=(const Session&) = delete;

  /// A new connection: its first request's header within the header timeout.
  void start() { read_request(); }

  /// After an answer on a kept-alive connection: the next request starts within the idle timeout.
  void read() {
    if (buffer_.size() > 0) return read_request();  // pipelined: already begun
    slot_.waiting(true);
    stream_.expires_after(shared_.options.idle_timeout);
    stream_.async_read_some(buffer_.prepare(kFirstRead),
                            [self = shared_from_this()](beast::error_code ec, std::size_t size) {
                              if (ec) return self->drop(ec, Closed::kIdleTimeout);
                              self->buffer_.commit(size);
                              self->read_request();
                            });
  }

  void evict() override {
    beast::error_code ignored;
    stream_.socket().shutdown(tcp::socket::shutdown_both, ignored);
    stream_.socket().close(ignored);
  }

 private:
  static constexpr std::size_t kFirstRead = 512;

  void read_request() {
    slot_.waiting(true);
    parser_.emplace();
    parser_->header_limit(MetricsServer::kMaxRequestHeader);
    parser_->body_limit(kMaxRequestBody);
    // The whole request within the timeout: a client that sends a byte a second is closed too.
    stream_.expires_after(shared_.options.header_timeout);
    http::async_read(stream_, buffer_, *parser_,
                     [self = shared_from_this()](beast::error_code ec, std::size_t) { self->on_read(ec); });
  }

  /// Ends the connection after a failed read; a timeout is counted as `timeout`.
  void drop(beast::error_code ec, Closed timeout) {
    if (ec == beast::error::timeout) shared_.count(timeout);
    slot_.leave();
    beast::error_code ignored;
    stream_.socket().shutdown(tcp::socket::shutdown_both, ignored);
  }

  void on_read(beast::error_code ec) {
    slot_.waiting(false);
    if (ec) {
      // Too long a header answers 431; anything else (timeout, a closed or garbled connection) is dropped.
      if (ec == http::error::header_limit)
        return respond(11, false, http::status::request_header_fields_too_large,
                       "request header too large\n");
      return drop(ec, Closed::kHeaderTimeout);
    }
    const auto& request = parser_->get();
    const unsigned version = request.version();
    const bool keep_alive = request.keep_alive();
    const bool head = request.method() == http::verb::head;
    if (request.method() != http::verb::get && !head)
      return respond(version, keep_alive, http::status::method_not_allowed, "GET or HEAD only\n");
    const auto raw = request.target();
    std::string_view target(raw.data(), raw.size());
    target = target.substr(0, target.find('?'));
    const SnapshotPointer snapshot = shared_.snapshot.load();
    if (target == "/metrics")
      return respond(version, keep_alive, http::status::ok,
                     head ? std::string()
                          : format_metrics(*snapshot, read_process_figures()) +
                                format_server_metrics(*snapshot, shared_),
                     kExpositionType);
    if (target == "/livez" || target == "/readyz" || target == "/healthz") {
      // /healthz: /readyz's older name, kept for the health checks that use it.
      const auto now = Clock::now();
      const bool live = is_live(*snapshot, now, shared_.options.max_snapshot_age);
      const bool ok = target == "/livez" ? live : is_ready(*snapshot, now, shared_.options.max_snapshot_age);
      const auto& stats = snapshot->stats;
      return respond(version, keep_alive, ok ? http::status::ok : http::status::service_unavailable,
                     ok      ? "ok\n"
                     : !live ? "stale: the gateway's loop has not reported for too long\n"
                     : stats.other_state_writers > 0
                         ? fmt::format("another writer of the state topic in this partition ({}): robots "
                                       "mixed\n",
                                       stats.other_state_writers)
                         : "link down\n");
    }
    respond(version, keep_alive, http::status::not_found,
            "not found: /metrics, /livez, /readyz and /healthz only\n");
  }

  void respond(unsigned version, bool keep_alive, http::status status, std::string body,
               std::string_view type = "text/plain; charset=utf-8") {
    stream_.expires_after(shared_.options.header_timeout);
    app::write_http_reply(shared_from_this(), stream_, "rsg_gateway", version, keep_alive,
                          {status, type, std::move(body)});
  }

  beast::tcp_stream stream_;
  Shared& shared_;
  app::ConnectionTable::Slot slot_;
  beast::flat_buffer buffer_;
  std::optional<http::request_parser<http::string_body>> parser_;
};

tcp::endpoint to_asio(const transport::Endpoint& endpoint) {
  tcp::endpoint out;
  std::memcpy(out.data(), endpoint.address(), endpoint.size());
  out.resize(endpoint.size());
  return out;
}

}  // namespace

struct MetricsServer::Impl {
  explicit Impl(const Options& options) : shared(options) {}

  Shared shared;  // first: the sessions the context destroys last still leave its table
  net::io_context io{1};
  tcp::acceptor acceptor{io};
  app::AcceptLoop accepting{acceptor, "metrics",
                            [this](tcp::socket socket) { on_connection(std::move(socket)); },
                            [this] { shared.table.evict_oldest_waiting(); }};
  std::jthread thread;  // named rsg-metrics

  void on_connection(tcp::socket socket) {
    beast::error_code ec;
    const auto remote = socket.remote_endpoint(ec);
    if (ec) return;  // gone already
    const auto admission = shared.table.make_room(remote.address());
    if (admission.limit)
      shared.count(*admission.limit == app::ConnectionLimit::kPerAddress ? Closed::kPerClientLimit
                                                                         : Closed::kTotalLimit);
    if (!admission.admitted) {
      // Every open connection is being answered: this one is closed at once.
      socket.close(ec);
      return;
    }
    std::make_shared<Session>(std::move(socket), shared, remote.address())->start();
  }
};

MetricsServer::MetricsServer(const Options& options, MetricsSnapshot first)
    : impl_(std::make_unique<Impl>(options)) {
  impl_->shared.snapshot.store(std::make_shared<const MetricsSnapshot>(std::move(first)));
  if (const auto ec = rsg::app::listen_on(impl_->acceptor, to_asio(options.listen)))
    throw EnvironmentError("--metrics: cannot listen on " + options.listen.to_string() + ": " + ec.message());
  impl_->accepting.start();
  impl_->thread = std::jthread([impl = impl_.get()] {
    ::pthread_setname_np(::pthread_self(), "rsg-metrics");
    impl->io.run();
  });
}

void MetricsServer::check_can_listen(const transport::Endpoint& listen) {
  net::io_context io;
  tcp::acceptor acceptor(io);
  if (const auto ec = rsg::app::listen_on(acceptor, to_asio(listen)))
    throw EnvironmentError("--metrics: cannot listen on " + listen.to_string() + ": " + ec.message());
}

MetricsServer::~MetricsServer() {
  // Sessions are owned by their pending operations: stopping the loop and destroying the context
  // destroys them on this thread, once the I/O thread has returned.
  std::promise<void> closed;
  net::post(impl_->io, [impl = impl_.get(), &closed] {
    impl->accepting.stop();
    closed.set_value();
  });
  closed.get_future().wait();
  impl_->io.stop();
  impl_->thread.join();
}

void MetricsServer::publish(MetricsSnapshot snapshot) {
  impl_->shared.snapshot.store(std::make_shared<const MetricsSnapshot>(std::move(snapshot)));
}

std::uint16_t MetricsServer::port() const { return impl_->acceptor.local_endpoint().port(); }

std::vector<std::string> MetricsServer::family_names() {
  return {"rsg_http_connections_open", "rsg_http_connections_closed_total"};
}

}  // namespace rsg::gateway
