// INTERNAL, not part of rsg's API and not installed (src/dds/internal/).
//
// Which participant announcements (SPDP DATA(p)) Fast DDS may see, so that made-up participants
// cannot fill its table of remote participants (kMaxRemoteParticipants) and keep real ones out.
// A participant is *proven* once a UDP message from its GUID prefix carries anything else than its
// announcement (an ACKNACK, a HEARTBEAT, a SEDP sample: what every real DDS participant sends
// within a second of discovering rsg's over the network); until then it is *on probation*:
//  - at most kMaxOnProbationPerSource participants from one source (address and port: a DDS
//    participant announces itself from a socket of its own), kMaxOnProbation in all, are on
//    probation at a time; an announcement of one more is dropped and counted
//    (RtpsGuardCounts::announcements_refused);
//  - its announcements reach Fast DDS with a lease of at most kProbationLease: one that stops
//    announcing itself is forgotten by Fast DDS, and leaves its place, within that, however long
//    the lease it claimed.
// A participant on this host that talks to rsg's over shared memory stays on probation (its
// announcements, over UDP multicast, keep renewing the shorter lease). A flood from one source
// therefore holds kMaxOnProbationPerSource places: real participants keep theirs and new ones are
// admitted at once (docs/security.md says what a flood from many sources does).
// Bounded: a fixed table of kTableSize participants, no allocation per datagram.
#pragma once

#include <array>
#include <chrono>
#include <cstdint>
#include <mutex>

namespace rsg::dds::internal {

inline constexpr std::chrono::seconds kProbationLease{30};
inline constexpr std::uint32_t kMaxOnProbation = 128;
inline constexpr std::uint32_t kMaxOnProbationPerSource = 4;
inline constexpr std::uint32_t kTableSize = 1024;

/// Where the announcement came from: a UDP address (IPv4 or IPv6, 16 bytes) and port.
struct AnnouncementSource {
  std::array<std::uint8_t, 16> address{};
  std::uint32_t port = 0;
  bool operator==(const AnnouncementSource& other) const noexcept {
    return address == other.address && port == other.port;
  }
};

class SpdpAdmission {
 public:
  using Clock = std::chrono::steady_clock;

  enum class Verdict : std::uint8_t {
    kPass,        ///< hand the datagram on as it is
    kShortLease,  ///< hand it on with the lease of its announcement cut to kProbationLease
    kRefuse,      ///< drop it: an announcement of one participant more on probation than allowed
  };

  /// What to do with a screened (well-formed) datagram of `size` bytes from `source` at `now`.
  /// With kShortLease, `lease_at` is the offset of the lease's seconds (an int32 in the
  /// announcement's byte order, `lease_little_endian`), or 0 when it names none (Fast DDS's
  /// default lease then applies: nothing to cut).
  struct Decision {
    Verdict verdict = Verdict::kPass;
    std::uint32_t lease_at = 0;
    bool lease_little_endian = true;
  };
  Decision admit(const std::uint8_t* datagram, std::uint32_t size, const AnnouncementSource& source,
                 Clock::time_point now) noexcept;

 private:
  struct Entry {
    std::array<std::uint8_t, 12> prefix{};
    AnnouncementSource source;
    Clock::time_point first_seen{};
    Clock::time_point last_seen{};
    bool used = false;
    bool proven = false;
    bool announced = false;  ///< an announcement of it was handed on: Fast DDS knows it
  };

  Entry* find(const std::uint8_t* prefix) noexcept;
  static bool active_on_probation(const Entry& entry, Clock::time_point now) noexcept;
  std::uint32_t on_probation(const AnnouncementSource* source, Clock::time_point now) const noexcept;

  std::mutex mutex_;  // receive threads of every transport of the participant
  std::array<Entry, kTableSize> table_{};
};

}  // namespace rsg::dds::internal
