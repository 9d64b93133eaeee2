// The gateway's flight recorder (--pcap-ring SECONDS --pcap-dir DIR): the raw datagrams of the last
// seconds, kept in memory and written as a pcap file on request (SIGUSR1) or when the link goes
// down, to answer "what did the robot send just before it failed".
//
// The ring is allocated at start-up, and the ingress receives straight into it
// (DatagramBatch::receive_into): recording costs per frame no allocation and no copy, only a
// timestamp and the sender's address. Datagrams from outside --allow-from are not kept (unless
// `all_sources`): a flood from elsewhere would push the robot's seconds out of the ring and fill
// every dump with the attacker's bytes; the robot's are moved up over their slots instead. Only a dump
// allocates: the ingress thread copies the window's datagrams out of the ring (`snapshot`), and another
// thread writes the file (`write`, DumpWriter), so that a slow or hung disk never holds frames in the
// socket's buffer.
#pragma once

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string_view>
#include <vector>

#include "capture/udp_packet.hpp"
#include "gateway/source_filter.hpp"
#include "rsg/transport/udp_socket.hpp"

namespace rsg::gateway {

class FlightRecorder {
 public:
  struct Options {
    std::chrono::duration<double> window{};  ///< how far back a dump reaches
    double expected_rate = 1000;             ///< sizes the ring: twice this rate over the window
    std::filesystem::path dir;               ///< where dumps go
    bool all_sources = false;                ///< keep datagrams `commit`'s filter rejects too
  };

  struct Dump {
    std::filesystem::path path;
    std::size_t frames = 0;
  };

  /// A dump's datagrams, copied out of the ring, ready to be written on any thread.
  struct Snapshot {
    struct Datagram {
      std::chrono::nanoseconds time{};  ///< arrival, since the Unix epoch
      capture::UdpEndpoint from;
      std::size_t offset = 0;  ///< into `bytes`
      std::uint32_t size = 0;
    };
    std::filesystem::path path;             ///< DIR/rsg_flight_<UTC time>_<N>_<reason>.pcap
    capture::UdpEndpoint to;                ///< the gateway's address
    std::vector<Datagram> datagrams;        ///< oldest first
    std::unique_ptr<std::uint8_t[]> bytes;  // not zeroed first: every byte is copied over
  };

  /// `listen`: the gateway's address, the destination in the dumps. `batch`: the receive batch the
  /// ring lends its slots to; one datagram of it takes at most `batch.buffer_bytes()`.
  FlightRecorder(const Options& options, const transport::Endpoint& listen,
                 const transport::DatagramBatch& batch);
  FlightRecorder(const FlightRecorder&) = delete;
  FlightRecorder& operator=(const FlightRecorder&) = delete;

  /// Datagrams the ring holds at most (beyond the window when they arrive faster than planned).
  std::size_t capacity() const { return kept_capacity_; }

  /// Before a receive: the batch's datagrams will land in the ring's next free slots.
  void lend(transport::DatagramBatch& batch);
  /// After it, once the batch's datagrams are handled (kept ones may move over skipped ones): the
  /// `received` datagrams of `batch` that `sources` allows (all with `all_sources`) become the
  /// newest entries, seen at `now`.
  void commit(const transport::DatagramBatch& batch, std::size_t received,
              std::chrono::system_clock::time_point now, const SourceFilter& sources);

  /// Datagrams `commit` did not keep (from outside `sources`) since start.
  std::uint64_t not_kept() const { return not_kept_; }

  /// Copies the datagrams of the last `window` before the newest one, oldest first, and names
  /// their file. Allocates: call it on a request or a link change, never per frame.
  Snapshot snapshot(std::string_view reason);

  /// Writes `snapshot` as a pcap file. @throws rsg::EnvironmentError when it cannot.
  static Dump write(const Snapshot& snapshot);

  /// At least the size of the file `write` makes of `snapshot` from its datagram `first` on.
  static std::uintmax_t file_bytes(const Snapshot& snapshot, std::size_t first = 0);
  /// Drops the oldest datagrams of `snapshot` until its file takes at most `max_bytes`; returns
  /// how many it dropped.
  static std::size_t keep_newest(Snapshot& snapshot, std::uintmax_t max_bytes);

 private:
  struct Entry {
    std::chrono::nanoseconds time{};  // since the Unix epoch
    std::uint32_t size = 0;
    capture::UdpEndpoint from;
  };

  std::uint8_t* slot(std::size_t index) { return storage_.data() + index * slot_bytes_; }

  Options options_;
  capture::UdpEndpoint listen_;
  std::size_t slot_bytes_;
  std::size_t slots_;          // ring size: kept_capacity_ plus one batch being received into
  std::size_t kept_capacity_;  // entries that are never lent out while they count
  std::vector<std::uint8_t> storage_;
  std::vector<Entry> entries_;
  std::size_t next_ = 0;   // the slot the next datagram goes to
  std::size_t count_ = 0;  // valid entries, ending just before next_
  std::uint64_t dumps_ = 0;
  std::uint64_t not_kept_ = 0;
};

}  // namespace rsg::gateway
