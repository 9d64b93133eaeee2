#include "capture/pcap_file.hpp"

#include <pcap/pcap.h>

#include <stdexcept>

#include "rsg/error.hpp"

namespace rsg::capture {

void PcapReader::Close::operator()(pcap* handle) const { pcap_close(handle); }

PcapReader::PcapReader(const std::string& path) {
  char error[PCAP_ERRBUF_SIZE] = "";
  start(pcap_open_offline_with_tstamp_precision(path.c_str(), PCAP_TSTAMP_PRECISION_NANO, error), path,
        error);
}

PcapReader::PcapReader(std::FILE* stream) {
  char error[PCAP_ERRBUF_SIZE] = "";
  pcap* handle = pcap_fopen_offline_with_tstamp_precision(stream, PCAP_TSTAMP_PRECISION_NANO, error);
  if (handle == nullptr) std::fclose(stream);  // on success the handle owns the stream
  start(handle, "stream", error);
}

void PcapReader::start(pcap* handle, const std::string& name, const char* error) {
  name_ = name;
  if (handle == nullptr) throw InputError("cannot read '" + name + "': " + error);
  handle_.reset(handle);
  linktype_ = pcap_datalink(handle);
  if (!UdpExtractor::supports(linktype_)) {
    const char* link_name = pcap_datalink_val_to_name(linktype_);
    throw InputError("'" + name + "': link type " + (link_name ? link_name : "?") + " (" +
                     std::to_string(linktype_) + ") is not supported");
  }
  extractor_.emplace(linktype_);
}

std::optional<UdpPacket> PcapReader::next() {
  for (;;) {
    pcap_pkthdr* header = nullptr;
    const std::uint8_t* bytes = nullptr;
    const int status = pcap_next_ex(handle_.get(), &header, &bytes);
    if (status == PCAP_ERROR_BREAK) return std::nullopt;  // end of file
    if (status != 1)
      throw InputError("'" + name_ + "' is damaged: " + std::string(pcap_geterr(handle_.get())));
    const std::chrono::nanoseconds time =
        std::chrono::seconds(header->ts.tv_sec) + std::chrono::nanoseconds(header->ts.tv_usec);
    if (auto packet = extractor_->extract(time, {bytes, header->caplen})) return packet;
  }
}

void PcapWriter::Close::operator()(pcap* handle) const { pcap_close(handle); }
void PcapWriter::Close::operator()(pcap_dumper* dumper) const { pcap_dump_close(dumper); }

PcapWriter::PcapWriter(const std::string& path)
    : path_(path), dead_(pcap_open_dead(DLT_RAW, static_cast<int>(kMaxIpUdpHeader + kMaxUdpPayload))) {
  if (!dead_) throw EnvironmentError("cannot write '" + path + "': libpcap refused raw IP");
  dumper_.reset(pcap_dump_open(dead_.get(), path.c_str()));
  if (!dumper_)
    throw EnvironmentError("cannot write '" + path + "': " + std::string(pcap_geterr(dead_.get())));
}

PcapWriter::PcapWriter(std::FILE* file, const std::string& path)
    : path_(path), dead_(pcap_open_dead(DLT_RAW, static_cast<int>(kMaxIpUdpHeader + kMaxUdpPayload))) {
  if (!dead_) {
    std::fclose(file);
    throw EnvironmentError("cannot write '" + path + "': libpcap refused raw IP");
  }
  // Owns `file` from here on, closed with it. When it fails writing the header, libpcap has closed
  // `file` itself (pcap_setup_dump), so it is not closed again here.
  dumper_.reset(pcap_dump_fopen(dead_.get(), file));
  if (!dumper_)
    throw EnvironmentError("cannot write '" + path + "': " + std::string(pcap_geterr(dead_.get())));
}

bool PcapWriter::write(const UdpPacket& packet) {
  const std::size_t size = encode_raw_ip(packet.from, packet.to, packet.payload, packet_);
  if (size == 0) return false;
  pcap_pkthdr header{};
  const auto micros = std::chrono::duration_cast<std::chrono::microseconds>(packet.time).count();
  header.ts.tv_sec = static_cast<time_t>(micros / 1'000'000);
  header.ts.tv_usec = static_cast<suseconds_t>(micros % 1'000'000);
  header.caplen = header.len = static_cast<bpf_u_int32>(size);
  pcap_dump(reinterpret_cast<u_char*>(dumper_.get()), &header, packet_.data());
  return true;
}

void PcapWriter::flush() {
  if (pcap_dump_flush(dumper_.get()) != 0 || std::ferror(pcap_dump_file(dumper_.get())))
    throw EnvironmentError("cannot write '" + path_ + "'");
}

}  // namespace rsg::capture
