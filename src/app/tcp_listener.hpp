// How rsg's TCP servers (rsg_gateway's /metrics, rsg_view's page) start listening, in one place.
#pragma once

#include <boost/asio/ip/tcp.hpp>
#include <boost/system/error_code.hpp>

namespace rsg::app {

/// Opens `acceptor` on `endpoint`'s protocol, binds it with SO_REUSEADDR (a restarted server gets
/// its port back while the old connections linger in TIME_WAIT) and listens. Returns the first
/// failure, for the caller to turn into its own error; the acceptor is then unusable.
inline boost::system::error_code listen_on(boost::asio::ip::tcp::acceptor& acceptor,
                                           const boost::asio::ip::tcp::endpoint& endpoint) {
  namespace net = boost::asio;
  boost::system::error_code ec;
  acceptor.open(endpoint.protocol(), ec);
  if (!ec) acceptor.set_option(net::socket_base::reuse_address(true), ec);
  if (!ec) acceptor.bind(endpoint, ec);
  if (!ec) acceptor.listen(net::socket_base::max_listen_connections, ec);
  return ec;
}

}  // namespace rsg::app
