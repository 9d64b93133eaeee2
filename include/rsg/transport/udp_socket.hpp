// A UDP socket that owns its file descriptor, the address type it talks to, and the preallocated
// storage of batch receives.
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
#include <vector>

#include "rsg/error.hpp"

namespace rsg::transport {

/// An IPv4 or IPv6 address and port.
class Endpoint {
 public:
  Endpoint() = default;
  /// Parses "HOST:PORT" or "[V6]:PORT"; HOST may be a name (resolved here).
  /// @throws rsg::InputError naming the input when it is malformed or the name does not resolve.
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

/// Storage for `UdpSocket::receive_batch`: `capacity` buffers of `buffer_bytes` each, their
/// senders and the kernel's message headers, allocated once and reused by every receive.
///
/// A datagram longer than `buffer_bytes` is cut to fit; it keeps its real size and is marked
/// truncated, so a caller can reject it instead of reading its first bytes as a whole message.
class DatagramBatch {
 public:
  struct Datagram {
    std::span<const std::uint8_t> bytes;  ///< what was kept: at most `buffer_bytes`
    std::size_t size;                     ///< the datagram's real size
    bool truncated;                       ///< longer than its buffer: `bytes` is only its start
    const Endpoint& from;
    /// When the kernel queued it (UdpSocket::timestamp_arrivals); the epoch when it did not say.
    std::chrono::system_clock::time_point arrived;
  };

  DatagramBatch(std::size_t capacity, std::size_t buffer_bytes);
  // The kernel headers point into this object's own storage.
  DatagramBatch(const DatagramBatch&) = delete;
  DatagramBatch& operator=(const DatagramBatch&) = delete;

  std::size_t capacity() const { return headers_.size(); }
  std::size_t buffer_bytes() const { return buffer_bytes_; }
  /// Datagrams held from the last `receive_batch`.
  std::size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }
  Datagram operator[](std::size_t index) const;

  /// Makes the next receives put datagram `index` into `buffer` (at least `buffer_bytes()` long)
  /// instead of the batch's own storage, so that a caller can receive straight into storage it
  /// keeps (the gateway's flight recorder) without copying. The buffer must outlive its use.
  void receive_into(std::size_t index, std::span<std::uint8_t> buffer);

 private:
  friend class UdpSocket;

  std::size_t buffer_bytes_;
  std::size_t size_ = 0;
  std::vector<std::uint8_t> storage_;  // capacity * buffer_bytes, one slot per datagram
  std::vector<Endpoint> senders_;
  std::vector<iovec> slots_;
  std::vector<mmsghdr> headers_;
  // Per datagram, room for its arrival time stamp (a cmsghdr and a timespec), cmsghdr-aligned.
  static constexpr std::size_t kControlWords = 8;
  std::vector<std::uint64_t> control_;
};

class UdpSocket {
 public:
  /// A socket bound to `local` (port 0 picks a free one).
  /// @throws rsg::EnvironmentError naming the address when the kernel refuses (e.g. in use).
  static UdpSocket bind(const Endpoint& local);
  /// An unbound socket of the family of `peer`, for sending.
  /// @throws rsg::EnvironmentError when the kernel refuses a socket.
  static UdpSocket for_sending_to(const Endpoint& peer);

  UdpSocket(UdpSocket&& other) noexcept;
  UdpSocket& operator=(UdpSocket&& other) noexcept;
  UdpSocket(const UdpSocket&) = delete;
  UdpSocket& operator=(const UdpSocket&) = delete;
  ~UdpSocket();

  /// Waits up to `timeout` for one datagram. The per-frame path: never throws.
  /// @return its full size (which may exceed `buffer.size()`: the datagram was truncated), or
  /// nothing on timeout or EINTR.
  std::optional<std::size_t> receive(std::span<std::uint8_t> buffer, Endpoint* from,
                                     std::chrono::milliseconds timeout);
  /// Waits up to `timeout` for a datagram to be queued.
  /// @return false on timeout or EINTR.
  bool wait_readable(std::chrono::milliseconds timeout);
  /// Takes the datagrams already queued, at most `batch.capacity()`, in one system call (recvmmsg)
  /// and without waiting.
  /// @return how many `batch` now holds: 0 when none was queued.
  std::size_t receive_batch(DatagramBatch& batch);
  /// Sends one datagram.
  /// @return false (errno kept) when the kernel refused it.
  bool send_to(std::span<const std::uint8_t> datagram, const Endpoint& to);

  /// Makes the kernel stamp every datagram with the time it was queued (SO_TIMESTAMPNS), which
  /// `receive_batch` hands out as Datagram::arrived: what a busy receiver was doing meanwhile does
  /// not move it.
  /// @throws rsg::EnvironmentError when the kernel refuses.
  void timestamp_arrivals();
  /// Whether a datagram is queued now (never waits).
  bool has_queued() { return wait_readable(std::chrono::milliseconds(0)); }

  /// Asks for a larger kernel receive buffer so bursts at 1 kHz+ are not dropped.
  /// @return the size the kernel granted.
  int set_receive_buffer(int bytes);
  Endpoint local_endpoint() const;
  int fd() const { return fd_; }

 private:
  explicit UdpSocket(int fd) : fd_(fd) {}
  int fd_ = -1;
};

}  // namespace rsg::transport
