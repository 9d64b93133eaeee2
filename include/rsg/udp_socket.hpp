// A UDP socket that owns its file descriptor, and the address type it talks to.
#pragma once

#include <netinet/in.h>
#include <sys/socket.h>

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>

namespace rsg {

/// An IPv4 or IPv6 address and port.
class Endpoint {
 public:
  Endpoint() = default;
  /// Parses "HOST:PORT" or "[V6]:PORT"; HOST may be a name. Throws std::invalid_argument with a
  /// message that names the input.
  static Endpoint parse(std::string_view host_port);

  const sockaddr* address() const { return reinterpret_cast<const sockaddr*>(&storage_); }
  sockaddr* address() { return reinterpret_cast<sockaddr*>(&storage_); }
  socklen_t size() const { return size_; }
  socklen_t capacity() const { return sizeof storage_; }
  void set_size(socklen_t size) { size_ = size; }
  int family() const { return storage_.ss_family; }
  std::uint16_t port() const;
  std::string to_string() const;

  friend bool operator==(const Endpoint& a, const Endpoint& b);

 private:
  sockaddr_storage storage_{};
  socklen_t size_ = 0;
};

class UdpSocket {
 public:
  /// A socket bound to `local` (port 0 picks a free one). Throws std::system_error naming the address.
  static UdpSocket bind(const Endpoint& local);
  /// An unbound socket of the family of `peer`, for sending.
  static UdpSocket for_sending_to(const Endpoint& peer);

  UdpSocket(UdpSocket&& other) noexcept;
  UdpSocket& operator=(UdpSocket&& other) noexcept;
  UdpSocket(const UdpSocket&) = delete;
  UdpSocket& operator=(const UdpSocket&) = delete;
  ~UdpSocket();

  /// Waits up to `timeout` for one datagram. Returns its full size (which may exceed
  /// `buffer.size()`: the datagram was truncated) or nothing on timeout or EINTR.
  std::optional<std::size_t> receive(std::span<std::uint8_t> buffer, Endpoint* from,
                                     std::chrono::milliseconds timeout);
  /// Sends one datagram; false (errno kept) when the kernel refused it.
  bool send_to(std::span<const std::uint8_t> datagram, const Endpoint& to);

  /// Asks for a larger kernel receive buffer so bursts at 1 kHz+ are not dropped; returns what
  /// the kernel granted.
  int set_receive_buffer(int bytes);
  Endpoint local_endpoint() const;
  int fd() const { return fd_; }

 private:
  explicit UdpSocket(int fd) : fd_(fd) {}
  int fd_ = -1;
};

}  // namespace rsg
