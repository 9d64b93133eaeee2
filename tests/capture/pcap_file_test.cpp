// PcapWriter and PcapReader: what one writes the other reads back (pcap), a pcapng file of the same
// datagrams reads the same, and a file cut anywhere reads its whole packets and then ends (cut
// between two packets) or throws rsg::InputError (cut inside one), never a wrong datagram.
#include "capture/pcap_file.hpp"

#include <gtest/gtest.h>
#include <pcap/pcap.h>
#include <unistd.h>

#include <array>
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "capture/udp_packet.hpp"
#include "rsg/error.hpp"

namespace rsg::capture {
namespace {

using Bytes = std::vector<std::uint8_t>;
using std::chrono::nanoseconds;

// LINKTYPE_RAW as pcapng stores it (libpcap reports it as DLT_RAW).
constexpr std::uint16_t kLinktypeRaw = 101;

// A scratch file that is removed with the test.
class ScratchFile {
 public:
  explicit ScratchFile(const std::string& name)
      : path_(std::filesystem::temp_directory_path() /
              ("rsg_capture_" + std::to_string(::getpid()) + "_" + name)) {}
  ~ScratchFile() { std::filesystem::remove(path_); }
  ScratchFile(const ScratchFile&) = delete;
  ScratchFile& operator=(const ScratchFile&) = delete;

  std::string path() const { return path_.string(); }
  void write(const Bytes& bytes, std::size_t size) const {
    std::ofstream out(path_, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(size));
  }
  Bytes read() const {
    std::ifstream in(path_, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  }

 private:
  std::filesystem::path path_;
};

UdpEndpoint ipv4(std::uint8_t last, std::uint16_t port) {
  UdpEndpoint endpoint;
  endpoint.ip.version = 4;
  endpoint.ip.bytes = {10, 0, 0, last};
  endpoint.port = port;
  return endpoint;
}

UdpEndpoint ipv6(std::uint8_t last, std::uint16_t port) {
  UdpEndpoint endpoint;
  endpoint.ip.version = 6;
  endpoint.ip.bytes = {0xfd, 0x00, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, last};
  endpoint.port = port;
  return endpoint;
}

// What a test sends: a datagram's time, addresses and payload, owned.
struct Datagram {
  nanoseconds time;
  UdpEndpoint from;
  UdpEndpoint to;
  Bytes payload;
};

Bytes payload(std::size_t size, std::uint8_t seed) {
  Bytes bytes(size);
  for (std::size_t i = 0; i < size; ++i) bytes[i] = static_cast<std::uint8_t>(seed + i * 7);
  return bytes;
}

// Microsecond times, since classic pcap keeps no more; a full SEND_BUF frame (2137 bytes) among them.
std::vector<Datagram> datagrams() {
  return {
      {nanoseconds(1'700'000'000'123'456'000), ipv4(2, 17001), ipv4(1, 17000), payload(2137, 1)},
      {nanoseconds(1'700'000'000'124'457'000), ipv4(2, 17001), ipv4(1, 17000), payload(1, 2)},
      {nanoseconds(1'700'000'001'000'000'000), ipv6(2, 40000), ipv6(1, 17000), payload(200, 3)},
  };
}

void expect_same(const Datagram& read, const Datagram& sent) {
  EXPECT_EQ(read.time, sent.time);
  EXPECT_EQ(read.from.to_string(), sent.from.to_string());
  EXPECT_EQ(read.to.to_string(), sent.to.to_string());
  EXPECT_EQ(read.payload, sent.payload);
}

Datagram owned(const UdpPacket& packet) {
  return {packet.time, packet.from, packet.to, Bytes(packet.payload.begin(), packet.payload.end())};
}

// Writes `sent` with PcapWriter; returns the file's bytes and where each record ends.
constexpr std::size_t kPcapFileHeader = 24;

Bytes written_pcap(const std::vector<Datagram>& sent, std::vector<std::size_t>& record_ends) {
  const ScratchFile file("written.pcap");
  {
    PcapWriter writer(file.path());
    for (const Datagram& datagram : sent)
      EXPECT_TRUE(writer.write({datagram.time, datagram.from, datagram.to, datagram.payload}));
    writer.flush();
  }
  const Bytes bytes = file.read();
  constexpr std::size_t kRecordHeader = 16;
  record_ends.clear();
  std::size_t at = kPcapFileHeader;
  for (const Datagram& datagram : sent) {
    std::array<std::uint8_t, kMaxIpUdpHeader + kMaxUdpPayload> packet{};
    at += kRecordHeader + encode_raw_ip(datagram.from, datagram.to, datagram.payload, packet);
    record_ends.push_back(at);
  }
  EXPECT_EQ(at, bytes.size());
  return bytes;
}

void append_u16(Bytes& out, std::uint16_t value) {
  for (int i = 0; i < 2; ++i) out.push_back(static_cast<std::uint8_t>(value >> (8 * i)));
}
void append_u32(Bytes& out, std::uint32_t value) {
  for (int i = 0; i < 4; ++i) out.push_back(static_cast<std::uint8_t>(value >> (8 * i)));
}

// A pcapng block: type, total length, body (padded to 4 bytes), total length again.
void append_block(Bytes& out, std::uint32_t type, Bytes body) {
  body.resize((body.size() + 3) / 4 * 4);
  const auto total = static_cast<std::uint32_t>(body.size() + 12);
  append_u32(out, type);
  append_u32(out, total);
  out.insert(out.end(), body.begin(), body.end());
  append_u32(out, total);
}

// The same datagrams as a pcapng file, written here by the format's description (libpcap writes no
// pcapng): a section header, one raw-IP interface with nanosecond times, an enhanced packet block
// per datagram. Returns the bytes, where the interface block ends and where each packet block ends.
Bytes pcapng_of(const std::vector<Datagram>& sent, std::size_t& header_end,
                std::vector<std::size_t>& block_ends) {
  Bytes file;
  Bytes section;
  append_u32(section, 0x1A2B3C4D);  // byte-order magic
  append_u16(section, 1);           // version 1.0
  append_u16(section, 0);
  append_u32(section, 0xFFFFFFFF);  // section length: not given
  append_u32(section, 0xFFFFFFFF);
  append_block(file, 0x0A0D0D0A, section);

  Bytes interface;
  append_u16(interface, kLinktypeRaw);
  append_u16(interface, 0);
  append_u32(interface, 0);  // snaplen: none
  append_u16(interface, 9);  // if_tsresol
  append_u16(interface, 1);
  interface.push_back(9);  // 10^-9 s
  interface.resize(interface.size() + 3);
  append_u32(interface, 0);  // opt_endofopt
  append_block(file, 0x00000001, interface);
  header_end = file.size();

  block_ends.clear();
  for (const Datagram& datagram : sent) {
    std::array<std::uint8_t, kMaxIpUdpHeader + kMaxUdpPayload> packet{};
    const std::size_t size = encode_raw_ip(datagram.from, datagram.to, datagram.payload, packet);
    const auto time = static_cast<std::uint64_t>(datagram.time.count());
    Bytes body;
    append_u32(body, 0);  // interface 0
    append_u32(body, static_cast<std::uint32_t>(time >> 32));
    append_u32(body, static_cast<std::uint32_t>(time));
    append_u32(body, static_cast<std::uint32_t>(size));
    append_u32(body, static_cast<std::uint32_t>(size));
    body.insert(body.end(), packet.begin(), packet.begin() + static_cast<std::ptrdiff_t>(size));
    append_block(file, 0x00000006, body);
    block_ends.push_back(file.size());
  }
  return file;
}

// Reads `file` to its end; the packets read, or (`threw`) those read before rsg::InputError.
std::vector<Datagram> read_all(const std::string& path, bool& threw) {
  std::vector<Datagram> read;
  threw = false;
  try {
    PcapReader reader(path);
    while (const std::optional<UdpPacket> packet = reader.next()) read.push_back(owned(*packet));
  } catch (const InputError&) {
    threw = true;
  }
  return read;
}

// Every cut of `bytes`, whose header ends at `header_end` and whose records end at `record_ends`:
// the reader gives the packets of the records that end at or before the cut, each equal to what
// was sent; then it ends when the cut is where the header or a record ends, and throws
// rsg::InputError when the cut is anywhere else (inside the header or a record).
void expect_every_cut_reads_its_whole_packets(const Bytes& bytes, std::size_t header_end,
                                              const std::vector<std::size_t>& record_ends,
                                              const std::vector<Datagram>& sent, const char* name) {
  const ScratchFile file(name);
  for (std::size_t cut = 0; cut < bytes.size(); ++cut) {
    file.write(bytes, cut);
    bool threw = false;
    const std::vector<Datagram> read = read_all(file.path(), threw);
    std::size_t whole = 0;
    while (whole < record_ends.size() && record_ends[whole] <= cut) ++whole;
    ASSERT_EQ(read.size(), whole) << name << " cut at " << cut;
    for (std::size_t i = 0; i < whole; ++i) expect_same(read[i], sent[i]);
    const bool at_an_end = cut == header_end || (whole > 0 && record_ends[whole - 1] == cut);
    EXPECT_EQ(threw, !at_an_end) << name << " cut at " << cut
                                 << (at_an_end ? ": where a block ends, yet an error"
                                               : ": inside a block, yet no error");
  }
}

// A raw-IP capture that reads as `sent`, datagram by datagram, and ends there.
void expect_reads_exactly(const std::string& path, const std::vector<Datagram>& sent) {
  PcapReader reader(path);
  EXPECT_EQ(reader.linktype(), DLT_RAW);
  for (const Datagram& datagram : sent) {
    const std::optional<UdpPacket> packet = reader.next();
    ASSERT_TRUE(packet);
    expect_same(owned(*packet), datagram);
  }
  EXPECT_FALSE(reader.next());
}

TEST(PcapFile, WhatThePcapWriterWritesTheReaderReadsBackExactly) {
  const std::vector<Datagram> sent = datagrams();
  std::vector<std::size_t> record_ends;
  const Bytes bytes = written_pcap(sent, record_ends);
  const ScratchFile file("round_trip.pcap");
  file.write(bytes, bytes.size());
  expect_reads_exactly(file.path(), sent);
}

TEST(PcapFile, APcapngFileOfTheSameDatagramsReadsTheSameWithItsNanoseconds) {
  std::vector<Datagram> sent = datagrams();
  sent[1].time += nanoseconds(789);  // pcapng with if_tsresol 9 keeps nanoseconds
  std::size_t header_end = 0;
  std::vector<std::size_t> block_ends;
  const Bytes bytes = pcapng_of(sent, header_end, block_ends);
  const ScratchFile file("round_trip.pcapng");
  file.write(bytes, bytes.size());
  expect_reads_exactly(file.path(), sent);
}

TEST(PcapFile, EveryCutOfAPcapFileReadsItsWholePacketsThenEndsOrThrowsInputError) {
  const std::vector<Datagram> sent = datagrams();
  std::vector<std::size_t> record_ends;
  const Bytes bytes = written_pcap(sent, record_ends);
  expect_every_cut_reads_its_whole_packets(bytes, kPcapFileHeader, record_ends, sent, "cut.pcap");
}

TEST(PcapFile, EveryCutOfAPcapngFileReadsItsWholePacketsThenEndsOrThrowsInputError) {
  const std::vector<Datagram> sent = datagrams();
  std::size_t header_end = 0;
  std::vector<std::size_t> block_ends;
  const Bytes bytes = pcapng_of(sent, header_end, block_ends);
  expect_every_cut_reads_its_whole_packets(bytes, header_end, block_ends, sent, "cut.pcapng");
}

TEST(PcapFile, AMissingFileOrOneThatIsNoCaptureIsAnInputErrorNamingIt) {
  const ScratchFile missing("missing.pcap");
  try {
    PcapReader reader(missing.path());
    FAIL() << "no error for a missing file";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find(missing.path()), std::string::npos) << error.what();
  }
  const ScratchFile text("text.pcap");
  const std::string words = "not a capture file, only words\n";
  text.write(Bytes(words.begin(), words.end()), words.size());
  EXPECT_THROW(PcapReader{text.path()}, InputError);
}

}  // namespace
}  // namespace rsg::capture
