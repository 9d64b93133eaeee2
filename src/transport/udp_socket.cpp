#include "rsg/transport/udp_socket.hpp"

#include <arpa/inet.h>
#include <netdb.h>
#include <poll.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <string>

#include "rsg/error.hpp"
#include "rsg/transport/host_port.hpp"

namespace rsg::transport {

Endpoint Endpoint::parse(std::string_view host_port) {
  const std::string text(host_port);
  wire::Parsed<HostPort> parts = parse_host_port(text, HostPortRule::kBindAddress);
  if (!parts) throw InputError(parts.error());
  std::string host = parts->host;
  const std::string port = std::to_string(parts->port);
  if (host.size() >= 2 && host.front() == '[' && host.back() == ']') host = host.substr(1, host.size() - 2);
  if (host.empty() || host == "*") host = "0.0.0.0";

  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_DGRAM;
  hints.ai_flags = AI_NUMERICSERV;
  addrinfo* found = nullptr;
  if (const int status = ::getaddrinfo(host.c_str(), port.c_str(), &hints, &found); status != 0)
    throw InputError("'" + text + "': " + ::gai_strerror(status));
  Endpoint endpoint;
  std::memcpy(&endpoint.storage_, found->ai_addr, found->ai_addrlen);
  endpoint.size_ = static_cast<socklen_t>(found->ai_addrlen);
  ::freeaddrinfo(found);
  return endpoint;
}

std::uint16_t Endpoint::port() const {
  if (family() == AF_INET) return ntohs(reinterpret_cast<const sockaddr_in*>(&storage_)->sin_port);
  if (family() == AF_INET6) return ntohs(reinterpret_cast<const sockaddr_in6*>(&storage_)->sin6_port);
  return 0;
}

std::string Endpoint::to_string() const {
  char host[INET6_ADDRSTRLEN] = "?";
  if (family() == AF_INET) {
    ::inet_ntop(AF_INET, &reinterpret_cast<const sockaddr_in*>(&storage_)->sin_addr, host, sizeof host);
    return std::string(host) + ":" + std::to_string(port());
  }
  if (family() == AF_INET6) {
    ::inet_ntop(AF_INET6, &reinterpret_cast<const sockaddr_in6*>(&storage_)->sin6_addr, host, sizeof host);
    return "[" + std::string(host) + "]:" + std::to_string(port());
  }
  return "(none)";
}

bool operator==(const Endpoint& a, const Endpoint& b) {
  return a.size_ == b.size_ && std::memcmp(&a.storage_, &b.storage_, a.size_) == 0;
}

DatagramBatch::DatagramBatch(std::size_t capacity, std::size_t buffer_bytes)
    : buffer_bytes_(buffer_bytes),
      storage_(capacity * buffer_bytes),
      senders_(capacity),
      slots_(capacity),
      headers_(capacity),
      control_(capacity * kControlWords) {
  static_assert(CMSG_SPACE(sizeof(timespec)) <= kControlWords * sizeof(std::uint64_t));
  for (std::size_t i = 0; i < capacity; ++i) {
    slots_[i] = {storage_.data() + i * buffer_bytes, buffer_bytes};
    msghdr& header = headers_[i].msg_hdr;
    header.msg_iov = &slots_[i];
    header.msg_iovlen = 1;
    header.msg_name = senders_[i].address();
  }
}

void DatagramBatch::receive_into(std::size_t index, std::span<std::uint8_t> buffer) {
  slots_[index] = {buffer.data(), std::min(buffer.size(), buffer_bytes_)};
}

DatagramBatch::Datagram DatagramBatch::operator[](std::size_t index) const {
  const mmsghdr& header = headers_[index];
  // With MSG_TRUNC in the receive flags msg_len is the real size; msg_flags says whether it was cut.
  const bool truncated = (header.msg_hdr.msg_flags & MSG_TRUNC) != 0 || header.msg_len > buffer_bytes_;
  const std::size_t kept = std::min<std::size_t>(header.msg_len, buffer_bytes_);
  std::chrono::system_clock::time_point arrived{};
  // The header is const here; CMSG_* want a mutable one and only read through it.
  auto& readable = const_cast<msghdr&>(header.msg_hdr);
  for (cmsghdr* message = CMSG_FIRSTHDR(&readable); message != nullptr;
       message = CMSG_NXTHDR(&readable, message)) {
    if (message->cmsg_level != SOL_SOCKET || message->cmsg_type != SCM_TIMESTAMPNS) continue;
    timespec stamp{};
    std::memcpy(&stamp, CMSG_DATA(message), sizeof stamp);
    arrived =
        std::chrono::system_clock::time_point(std::chrono::duration_cast<std::chrono::system_clock::duration>(
            std::chrono::seconds(stamp.tv_sec) + std::chrono::nanoseconds(stamp.tv_nsec)));
  }
  return {std::span(static_cast<const std::uint8_t*>(slots_[index].iov_base), kept), header.msg_len,
          truncated, senders_[index], arrived};
}

UdpSocket UdpSocket::bind(const Endpoint& local) {
  const int fd = ::socket(local.family(), SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (fd < 0) throw EnvironmentError(std::string("cannot open a UDP socket: ") + std::strerror(errno));
  // No SO_REUSEADDR: on UDP it would let a second process bind the same port and silently take
  // part of the stream. UDP has no TIME_WAIT, so a restarted gateway rebinds without it.
  UdpSocket socket(fd);
  if (::bind(fd, local.address(), local.size()) != 0)
    throw EnvironmentError("cannot bind UDP " + local.to_string() + ": " + std::strerror(errno));
  return socket;
}

UdpSocket UdpSocket::for_sending_to(const Endpoint& peer) {
  const int fd = ::socket(peer.family(), SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (fd < 0) throw EnvironmentError(std::string("cannot open a UDP socket: ") + std::strerror(errno));
  return UdpSocket(fd);
}

UdpSocket::UdpSocket(UdpSocket&& other) noexcept : fd_(other.fd_) { other.fd_ = -1; }

UdpSocket& UdpSocket::operator=(UdpSocket&& other) noexcept {
  if (this != &other) {
    if (fd_ >= 0) ::close(fd_);
    fd_ = other.fd_;
    other.fd_ = -1;
  }
  return *this;
}

UdpSocket::~UdpSocket() {
  if (fd_ >= 0) ::close(fd_);
}

std::optional<std::size_t> UdpSocket::receive(std::span<std::uint8_t> buffer, Endpoint* from,
                                              std::chrono::milliseconds timeout) {
  if (!wait_readable(timeout)) return std::nullopt;
  Endpoint ignored;
  Endpoint& source = from ? *from : ignored;
  socklen_t size = source.capacity();
  // MSG_TRUNC makes the kernel report the real datagram size, so oversized input is detectable.
  const ssize_t received = ::recvfrom(fd_, buffer.data(), buffer.size(), MSG_TRUNC, source.address(), &size);
  if (received < 0) return std::nullopt;
  source.set_size(size);
  return static_cast<std::size_t>(received);
}

bool UdpSocket::wait_readable(std::chrono::milliseconds timeout) {
  pollfd waiting{fd_, POLLIN, 0};
  return ::poll(&waiting, 1, static_cast<int>(timeout.count())) > 0;
}

std::size_t UdpSocket::receive_batch(DatagramBatch& batch) {
  batch.size_ = 0;
  for (std::size_t i = 0; i < batch.headers_.size(); ++i) {
    msghdr& header = batch.headers_[i].msg_hdr;
    header.msg_namelen = sizeof(sockaddr_storage);  // the kernel shrinks it to the sender's
    header.msg_flags = 0;
    header.msg_control = &batch.control_[i * DatagramBatch::kControlWords];  // and this to what it wrote
    header.msg_controllen = DatagramBatch::kControlWords * sizeof(std::uint64_t);
  }
  const int received = ::recvmmsg(fd_, batch.headers_.data(), static_cast<unsigned>(batch.headers_.size()),
                                  MSG_DONTWAIT | MSG_TRUNC, nullptr);
  // EAGAIN: nothing queued. Any other error is the socket's, not one datagram's: the caller's next
  // wait reports it again or the socket recovers; either way there is nothing to hand out now.
  if (received <= 0) return 0;
  batch.size_ = static_cast<std::size_t>(received);
  for (std::size_t i = 0; i < batch.size_; ++i)
    batch.senders_[i].set_size(batch.headers_[i].msg_hdr.msg_namelen);
  return batch.size_;
}

bool UdpSocket::send_to(std::span<const std::uint8_t> datagram, const Endpoint& to) {
  return ::sendto(fd_, datagram.data(), datagram.size(), 0, to.address(), to.size()) ==
         static_cast<ssize_t>(datagram.size());
}

void UdpSocket::timestamp_arrivals() {
  const int on = 1;
  if (::setsockopt(fd_, SOL_SOCKET, SO_TIMESTAMPNS, &on, sizeof on) != 0)
    throw EnvironmentError(std::string("cannot time-stamp UDP arrivals (SO_TIMESTAMPNS): ") +
                           std::strerror(errno));
}

int UdpSocket::set_receive_buffer(int bytes) {
  ::setsockopt(fd_, SOL_SOCKET, SO_RCVBUF, &bytes, sizeof bytes);
  int granted = 0;
  socklen_t size = sizeof granted;
  ::getsockopt(fd_, SOL_SOCKET, SO_RCVBUF, &granted, &size);
  return granted;
}

Endpoint UdpSocket::local_endpoint() const {
  Endpoint endpoint;
  socklen_t size = endpoint.capacity();
  ::getsockname(fd_, endpoint.address(), &size);
  endpoint.set_size(size);
  return endpoint;
}

}  // namespace rsg::transport
