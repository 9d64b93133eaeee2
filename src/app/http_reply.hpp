// How rsg's HTTP servers (rsg_gateway's /metrics and /healthz, rsg_view's page) answer a request:
// the same headers, and the same rule for what follows the answer, in one place.
#pragma once

#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <memory>
#include <string>
#include <string_view>
#include <utility>

namespace rsg::app {

/// One answer: status, Content-Type and body (empty for a HEAD request).
struct HttpReply {
  boost::beast::http::status status;
  std::string_view content_type;
  std::string body;
};

/// Writes `reply` on `stream` as `server` for a request of HTTP `version` (10 or 11), with no
/// caching allowed. When the write is done, `session->read()` waits for the next request if the
/// connection stays open (`keep_alive`), else the sending side is shut down. `session` owns
/// `stream` and is kept alive until then.
template <class Session>
void write_http_reply(std::shared_ptr<Session> session, boost::beast::tcp_stream& stream,
                      std::string_view server, unsigned version, bool keep_alive, HttpReply reply) {
  namespace http = boost::beast::http;
  auto response = std::make_shared<http::response<http::string_body>>(reply.status, version);
  response->set(http::field::server, boost::beast::string_view(server.data(), server.size()));
  response->set(http::field::content_type,
                boost::beast::string_view(reply.content_type.data(), reply.content_type.size()));
  response->set(http::field::cache_control, "no-cache");
  response->keep_alive(keep_alive);
  response->body() = std::move(reply.body);
  response->prepare_payload();
  http::async_write(
      stream, *response,
      [session = std::move(session), &stream, response](boost::beast::error_code ec, std::size_t) {
        if (!ec && response->keep_alive()) return session->read();
        boost::beast::error_code ignored;
        stream.socket().shutdown(boost::asio::ip::tcp::socket::shutdown_send, ignored);
      });
}

}  // namespace rsg::app
