// The RTPS screen (src/dds/internal/rtps_screen.hpp) as a filter for tests in other languages:
// reads one datagram per line in hex from standard input and writes, per line, how many leading
// bytes the screen hands on to Fast DDS, the cut (none, trailing, misplaced, invalid) and, for an
// invalid one, the reason (`rsg_dds_screen_dropped_total`'s label). Used by
// wireshark.rtps_screen, whose oracle is tshark's RTPS dissector.
#include <cstdint>
#include <iostream>
#include <string>
#include <vector>

#include "dds/internal/rtps_screen.hpp"

namespace {

int nibble(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

const char* cut_name(rsg::dds::internal::RtpsScreen::Cut cut) {
  using Cut = rsg::dds::internal::RtpsScreen::Cut;
  switch (cut) {
    case Cut::kNone:
      return "none";
    case Cut::kTrailing:
      return "trailing";
    case Cut::kMisplaced:
      return "misplaced";
    case Cut::kInvalid:
      return "invalid";
  }
  return "?";
}

}  // namespace

int main() {
  std::string line;
  std::vector<std::uint8_t> datagram;
  while (std::getline(std::cin, line)) {
    datagram.clear();
    for (std::size_t i = 0; i + 1 < line.size(); i += 2) {
      const int high = nibble(line[i]), low = nibble(line[i + 1]);
      if (high < 0 || low < 0) {
        std::cerr << "rsg_rtps_screen_probe: not hex: " << line.substr(i, 2) << '\n';
        return 2;
      }
      datagram.push_back(static_cast<std::uint8_t>(high << 4 | low));
    }
    const auto screen = rsg::dds::internal::screen_rtps_datagram(datagram.data(),
                                                                 static_cast<std::uint32_t>(datagram.size()));
    std::cout << screen.forward_bytes << ' ' << cut_name(screen.cut) << ' '
              << (screen.cut == rsg::dds::internal::RtpsScreen::Cut::kInvalid
                      ? rsg::dds::to_string(screen.reason)
                      : "-")
              << '\n';
  }
  return 0;
}
