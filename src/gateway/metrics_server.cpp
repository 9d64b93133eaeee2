#include "metrics_server.hpp"

#include <pthread.h>
#include <spdlog/spdlog.h>

#include <atomic>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/post.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <cstring>
#include <future>
#include <optional>
#include <thread>

#include "http_reply.hpp"
#include "rsg/error.hpp"
#include "tcp_listener.hpp"

namespace rsg::gateway {
namespace {

namespace beast = boost::beast;
namespace http = beast::http;
namespace net = boost::asio;
using tcp = net::ip::tcp;

constexpr std::size_t kMaxRequestBody = 1024;  // GET and HEAD carry none
constexpr std::string_view kExpositionType = "text/plain; version=0.0.4; charset=utf-8";

using SnapshotPointer = std::shared_ptr<const MetricsSnapshot>;

/// What the I/O thread's connections share.
struct Shared {
  MetricsServer::Options options;
  std::atomic<SnapshotPointer> snapshot;
  std::size_t connections = 0;  // I/O thread only
};

/// One HTTP connection, alive while a read or write of it is pending.
class Session : public std::enable_shared_from_this<Session> {
 public:
  Session(tcp::socket&& socket, Shared& shared) : stream_(std::move(socket)), shared_(shared) {
    ++shared_.connections;
  }
  ~Session() { --shared_.connections; }
  Session(const Session&) = delete;
  Session& operator=(const Session&) = delete;

  void read() {
    parser_.emplace();
    parser_->header_limit(MetricsServer::kMaxRequestHeader);
    parser_->body_limit(kMaxRequestBody);
    // The whole request within the timeout: a client that sends a byte a second is closed too.
    stream_.expires_after(MetricsServer::kRequestTimeout);
    http::async_read(stream_, buffer_, *parser_,
                     [self = shared_from_this()](beast::error_code ec, std::size_t) { self->on_read(ec); });
  }

 private:
  void on_read(beast::error_code ec) {
    if (ec) {
      // Too long a header answers 431; anything else (timeout, a closed or garbled connection) is dropped.
      if (ec == http::error::header_limit)
        return respond(11, false, http::status::request_header_fields_too_large,
                       "request header too large\n");
      beast::error_code ignored;
      stream_.socket().shutdown(tcp::socket::shutdown_both, ignored);
      return;
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
                     head ? std::string() : format_metrics(*snapshot, read_process_figures()),
                     kExpositionType);
    if (target == "/livez" || target == "/readyz" || target == "/healthz") {
      // /healthz: /readyz's older name, kept for the health checks that use it.
      const auto now = Clock::now();
      const bool live = is_live(*snapshot, now, shared_.options.max_snapshot_age);
      const bool ok = target == "/livez" ? live : is_ready(*snapshot, now, shared_.options.max_snapshot_age);
      return respond(version, keep_alive, ok ? http::status::ok : http::status::service_unavailable,
                     ok     ? "ok\n"
                     : live ? "link down\n"
                            : "stale: the gateway's loop has not reported for too long\n");
    }
    respond(version, keep_alive, http::status::not_found,
            "not found: /metrics, /livez, /readyz and /healthz only\n");
  }

  void respond(unsigned version, bool keep_alive, http::status status, std::string body,
               std::string_view type = "text/plain; charset=utf-8") {
    stream_.expires_after(MetricsServer::kRequestTimeout);
    app::write_http_reply(shared_from_this(), stream_, "rsg_gateway", version, keep_alive,
                          {status, type, std::move(body)});
  }

  beast::tcp_stream stream_;
  Shared& shared_;
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
  Shared shared;  // first: the sessions the context destroys last still count themselves out of it
  net::io_context io{1};
  tcp::acceptor acceptor{io};
  std::thread thread;
  std::uint64_t refused = 0;

  void accept() {
    acceptor.async_accept([this](beast::error_code ec, tcp::socket socket) {
      if (ec == net::error::operation_aborted) return;
      if (!ec) {
        if (shared.connections < shared.options.max_connections) {
          std::make_shared<Session>(std::move(socket), shared)->read();
        } else {
          // Over the cap: closed at once. Logged once per power of two, not per connection.
          ++refused;
          if ((refused & (refused - 1)) == 0)
            spdlog::warn("metrics: {} connection(s) refused so far: {} already open", refused,
                         shared.options.max_connections);
          beast::error_code ignored;
          socket.close(ignored);
        }
      }
      accept();
    });
  }
};

MetricsServer::MetricsServer(const Options& options, MetricsSnapshot first)
    : impl_(std::make_unique<Impl>()) {
  impl_->shared.options = options;
  impl_->shared.snapshot.store(std::make_shared<const MetricsSnapshot>(std::move(first)));
  if (const auto ec = rsg::app::listen_on(impl_->acceptor, to_asio(options.listen)))
    throw EnvironmentError("--metrics: cannot listen on " + options.listen.to_string() + ": " + ec.message());
  impl_->accept();
  impl_->thread = std::thread([impl = impl_.get()] {
    ::pthread_setname_np(::pthread_self(), "rsg-metrics");
    impl->io.run();
  });
}

MetricsServer::~MetricsServer() {
  // Sessions are owned by their pending operations: stopping the loop and destroying the context
  // destroys them on this thread, once the I/O thread has returned.
  std::promise<void> closed;
  net::post(impl_->io, [impl = impl_.get(), &closed] {
    beast::error_code ignored;
    impl->acceptor.close(ignored);
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

}  // namespace rsg::gateway
