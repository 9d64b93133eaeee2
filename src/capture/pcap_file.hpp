// Reading and writing capture files with libpcap: pcap and pcapng in, pcap (raw IP) out.
#pragma once

#include <cstdio>
#include <memory>
#include <optional>
#include <string>

#include "capture/udp_packet.hpp"

struct pcap;
struct pcap_dumper;

namespace rsg::capture {

/// The UDP datagrams of a pcap or pcapng file, in file order, with nanosecond timestamps.
class PcapReader {
 public:
  /// @throws rsg::InputError naming the file and libpcap's reason, or the link type it cannot read.
  explicit PcapReader(const std::string& path);
  /// Reads from an open stream and closes it when done (tests and the fuzzer read from memory).
  explicit PcapReader(std::FILE* stream);

  /// The next UDP datagram; nothing at the end of the file.
  /// @throws rsg::InputError on a damaged or cut file (libpcap stops there).
  std::optional<UdpPacket> next();
  int linktype() const { return linktype_; }

 private:
  struct Close {
    void operator()(pcap* handle) const;
  };
  void start(pcap* handle, const std::string& name, const char* error);

  std::unique_ptr<pcap, Close> handle_;
  std::string name_;
  int linktype_ = 0;
  std::optional<UdpExtractor> extractor_;
};

/// Writes UDP datagrams as a classic pcap file of raw IP packets (LINKTYPE_RAW), microsecond
/// timestamps: what tcpdump, tshark and Wireshark all read.
class PcapWriter {
 public:
  /// @throws rsg::EnvironmentError naming the file.
  explicit PcapWriter(const std::string& path);
  /// Writes into `file`, already open for writing (the caller chose how: O_EXCL, O_NOFOLLOW), and
  /// closes it when done; `path` names it in errors. @throws rsg::EnvironmentError naming the file.
  PcapWriter(std::FILE* file, const std::string& path);

  /// False when the packet cannot be encoded (payload too large, mixed IP versions). Write errors
  /// show at `flush`.
  bool write(const UdpPacket& packet);
  /// @throws rsg::EnvironmentError when anything written so far did not reach the file.
  void flush();

 private:
  struct Close {
    void operator()(pcap* handle) const;
    void operator()(pcap_dumper* dumper) const;
  };
  std::string path_;
  std::unique_ptr<pcap, Close> dead_;
  std::unique_ptr<pcap_dumper, Close> dumper_;
  std::array<std::uint8_t, kMaxIpUdpHeader + kMaxUdpPayload> packet_{};
};

}  // namespace rsg::capture
