// rsg_flood: a hostile UDP sender for the reliability tests. Sends datagrams of the given sizes,
// cycling through them, in a tight sendto loop (or paced, with --rate) for --duration seconds or
// --count datagrams, and writes what it sent as JSON. Test helper, not a product.
//
// Every datagram is invalid with a known category, so the gateway's counters can be checked:
//   * size 0 .. 13            -> truncated (shorter than a header and CRC);
//   * size > 2137 (oversized) -> length_mismatch: a header claiming the largest valid data section
//                                (2123 bytes) followed by more bytes than that.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <cerrno>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <system_error>
#include <thread>
#include <vector>

namespace {

using Clock = std::chrono::steady_clock;

constexpr std::size_t kLargestUdpPayload = 65507;
constexpr std::uint16_t kLargestDataLength = 2123;  // docs/protocol.md: every field selected
constexpr std::uint8_t kStateRequest = 0x30;        // request type 3, packet number 0

/// An IPv4 UDP socket, closed when it goes out of scope.
class Socket {
 public:
  Socket() : fd_(::socket(AF_INET, SOCK_DGRAM, 0)) {
    if (fd_ < 0) throw std::system_error(errno, std::generic_category(), "socket");
  }
  ~Socket() { ::close(fd_); }
  Socket(const Socket&) = delete;
  Socket& operator=(const Socket&) = delete;

  /// True when the kernel took the datagram.
  bool send_to(const std::uint8_t* data, std::size_t size, const sockaddr_in& to) const {
    return ::sendto(fd_, data, size, 0, reinterpret_cast<const sockaddr*>(&to), sizeof to) ==
           static_cast<ssize_t>(size);
  }

 private:
  int fd_;
};

sockaddr_in parse_endpoint(const std::string& host_port) {
  const auto colon = host_port.rfind(':');
  if (colon == std::string::npos) throw std::invalid_argument("--to: expected HOST:PORT");
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(static_cast<std::uint16_t>(std::stoul(host_port.substr(colon + 1))));
  if (::inet_pton(AF_INET, host_port.substr(0, colon).c_str(), &address.sin_addr) != 1)
    throw std::invalid_argument("--to: '" + host_port.substr(0, colon) + "' is not an IPv4 address");
  return address;
}

/// The datagram of one size: a frame header claiming 2123 data bytes, then filler.
std::vector<std::uint8_t> datagram_of_size(std::size_t size) {
  std::vector<std::uint8_t> datagram(size, 0xA5);
  const std::uint8_t header[] = {kStateRequest, kLargestDataLength & 0xFF, kLargestDataLength >> 8};
  std::memcpy(datagram.data(), header, std::min(size, sizeof header));
  return datagram;
}

struct Options {
  std::string to;
  std::vector<std::size_t> sizes{0};
  double duration_s = 0;
  std::uint64_t count = 0;
  double rate_hz = 0;  // 0: as fast as the kernel takes them
  std::string report_path;
};

}  // namespace

int main(int argc, char** argv) {
  Options options;
  CLI::App app("Floods a UDP port with invalid datagrams of the given sizes", "rsg_flood");
  app.add_option("--to", options.to, "HOST:PORT")->required();
  app.add_option("--sizes", options.sizes, "Datagram sizes in bytes, cycled through")
      ->delimiter(',')
      ->check(CLI::Range(std::size_t{0}, kLargestUdpPayload));
  auto* duration = app.add_option("--duration", options.duration_s, "Seconds to send");
  app.add_option("--count", options.count, "Datagrams to send")->excludes(duration);
  app.add_option("--rate", options.rate_hz, "Datagrams per second (default: unpaced)");
  app.add_option("--report", options.report_path, "Write {sent, send_failures, seconds, by_size} here");
  CLI11_PARSE(app, argc, argv);
  if (options.duration_s <= 0 && options.count == 0) {
    std::cerr << "rsg_flood: give --duration or --count\n";
    return 2;
  }

  try {
    const sockaddr_in to = parse_endpoint(options.to);
    const Socket socket;
    std::vector<std::vector<std::uint8_t>> datagrams;
    for (const std::size_t size : options.sizes) datagrams.push_back(datagram_of_size(size));

    std::map<std::size_t, std::uint64_t> sent_by_size;
    std::uint64_t sent = 0;
    std::uint64_t failures = 0;
    const auto start = Clock::now();
    const auto end = start + std::chrono::duration_cast<Clock::duration>(
                                 std::chrono::duration<double>(options.duration_s));
    const auto period = options.rate_hz > 0 ? std::chrono::duration_cast<Clock::duration>(
                                                  std::chrono::duration<double>(1.0 / options.rate_hz))
                                            : Clock::duration::zero();
    for (std::uint64_t i = 0;; ++i) {
      if (options.count ? i == options.count : (i % 64 == 0 && Clock::now() >= end)) break;
      if (period > Clock::duration::zero()) std::this_thread::sleep_until(start + period * i);
      const auto& datagram = datagrams[i % datagrams.size()];
      if (socket.send_to(datagram.data(), datagram.size(), to)) {
        ++sent;
        ++sent_by_size[datagram.size()];
      } else {
        ++failures;
      }
    }
    const double seconds = std::chrono::duration<double>(Clock::now() - start).count();

    nlohmann::json by_size = nlohmann::json::object();
    for (const auto& [size, count] : sent_by_size) by_size[std::to_string(size)] = count;
    const std::string report = nlohmann::json{
        {"sent", sent},
        {"send_failures", failures},
        {"seconds", seconds},
        {"by_size", by_size}}.dump();
    std::cerr << "rsg_flood: " << report << "\n";
    if (!options.report_path.empty()) {
      std::ofstream out(options.report_path);
      out << report << "\n";
      if (!out) throw std::runtime_error("cannot write '" + options.report_path + "'");
    }
  } catch (const std::exception& error) {
    std::cerr << "rsg_flood: error: " << error.what() << "\n";
    return 1;
  }
  return 0;
}
