#include "dds/internal/spdp_admission.hpp"

#include <cstring>

#include "dds/internal/rtps_ids.hpp"

namespace rsg::dds::internal {
namespace {

/// How long a participant not heard from keeps its place in the table.
constexpr std::chrono::seconds kForgetAfter{60};
constexpr std::uint32_t kProbeWindow = 32;

std::uint32_t entity(const std::uint8_t* at) noexcept {
  return std::uint32_t{at[0]} << 24 | std::uint32_t{at[1]} << 16 | std::uint32_t{at[2]} << 8 | at[3];
}
std::uint16_t u16(const std::uint8_t* at, bool little) noexcept {
  return little ? static_cast<std::uint16_t>(at[0] | at[1] << 8)
                : static_cast<std::uint16_t>(at[0] << 8 | at[1]);
}

std::uint32_t slot_of(const std::uint8_t* prefix) noexcept {
  std::uint32_t hash = 2166136261u;  // FNV-1a
  for (int i = 0; i < 12; ++i) hash = (hash ^ prefix[i]) * 16777619u;
  return hash % kTableSize;
}

/// What a (screened) datagram holds: whether it announces a participant, where its lease is, and
/// whether it carries anything else a participant sends only once it has discovered rsg's.
struct Contents {
  bool announcement = false;
  bool other = false;
  std::uint32_t lease_at = 0;
  bool lease_little_endian = true;
};

/// The lease parameter of an SPDP sample's parameter list, or 0.
std::uint32_t find_lease(const std::uint8_t* datagram, std::uint32_t payload, std::uint32_t end,
                         bool& little) noexcept {
  if (end - payload < 4) return 0;
  little = datagram[payload + 1] == 0x03;
  std::uint32_t at = payload + 4;
  while (end - at >= 4) {
    const std::uint16_t pid = u16(datagram + at, little), length = u16(datagram + at + 2, little);
    if (pid == kPidSentinel || length > end - at - 4) return 0;
    if (pid == kPidLeaseDuration && length >= 8) return at + 4;
    at += 4 + ((length + 3u) & ~3u);
  }
  return 0;
}

Contents read_contents(const std::uint8_t* datagram, std::uint32_t size) noexcept {
  Contents contents;
  std::uint32_t at = kHeaderBytes;
  while (size - at >= 4) {
    const std::uint8_t id = datagram[at], flags = datagram[at + 1];
    const bool little = (flags & 0x01) != 0;
    std::uint32_t length = u16(datagram + at + 2, little);
    const std::uint32_t body = at + 4;
    if (length > size - body) break;
    const bool to_end = length == 0 && id != kInfoTimestamp && id != kPad;
    if (to_end) length = size - body;
    if (id == kData && length >= 20) {
      const std::uint32_t reader = entity(datagram + body + 4), writer = entity(datagram + body + 8);
      if (writer == kSpdpWriter || reader == kSpdpReader) {
        contents.announcement = true;
        const std::uint32_t to_inline_qos = u16(datagram + body + 2, little);
        // The screen has checked that the inline QoS list is well-formed; an SPDP sample from
        // Fast DDS, Cyclone or RTI carries none, and one that does keeps its lease (no cut).
        if ((flags & 0x02) == 0 && (flags & 0x04) != 0 && contents.lease_at == 0)
          contents.lease_at =
              find_lease(datagram, body + 4 + to_inline_qos, body + length, contents.lease_little_endian);
      } else {
        contents.other = true;
      }
    } else if (id != kPad && id != kInfoTimestamp && id != kInfoDestination && id != kInfoReply &&
               id != kInfoReplyIp4 && id != kInfoSource) {
      contents.other = true;
    }
    if (to_end) break;
    at = body + ((length + 3u) & ~3u);
  }
  return contents;
}

}  // namespace

SpdpAdmission::Entry* SpdpAdmission::find(const std::uint8_t* prefix) noexcept {
  const std::uint32_t first = slot_of(prefix);
  for (std::uint32_t i = 0; i < kProbeWindow; ++i) {
    Entry& entry = table_[(first + i) % kTableSize];
    if (entry.used && std::memcmp(entry.prefix.data(), prefix, 12) == 0) return &entry;
  }
  return nullptr;
}

bool SpdpAdmission::active_on_probation(const Entry& entry, Clock::time_point now) noexcept {
  return entry.used && !entry.proven && now - entry.last_seen < kProbationLease;
}

std::uint32_t SpdpAdmission::on_probation(const AnnouncementSource* source,
                                          Clock::time_point now) const noexcept {
  std::uint32_t count = 0;
  for (const Entry& entry : table_) {
    if (!active_on_probation(entry, now)) continue;
    if (source == nullptr || entry.source == *source) ++count;
  }
  return count;
}

SpdpAdmission::Decision SpdpAdmission::admit(const std::uint8_t* datagram, std::uint32_t size,
                                             const AnnouncementSource& source,
                                             Clock::time_point now) noexcept {
  if (size <= kHeaderBytes) return {};
  const Contents contents = read_contents(datagram, size);
  // A relayed announcement (INFO_SRC: a Discovery Server's, another participant's data) is judged
  // by its relay, which is the one that must be proven.
  const std::uint8_t* prefix = datagram + 8;
  std::lock_guard lock(mutex_);
  Entry* entry = find(prefix);
  if (contents.other) {
    if (entry != nullptr) {
      entry->proven = true;
      entry->last_seen = now;
    } else if (!contents.announcement) {
      // First heard from through something else than an announcement: a participant that
      // discovered rsg's through a Discovery Server or a peer list. Proven by what it sent.
      const std::uint32_t first = slot_of(prefix);
      for (std::uint32_t i = 0; i < kProbeWindow; ++i) {
        Entry& free = table_[(first + i) % kTableSize];
        if (!free.used || now - free.last_seen > kForgetAfter) {
          free = Entry{{}, source, now, now, true, true, false};
          std::memcpy(free.prefix.data(), prefix, 12);
          break;
        }
      }
    }
  }
  if (!contents.announcement) return {};
  if (entry != nullptr && entry->proven) {
    entry->last_seen = now;
    entry->announced = true;
    return {};
  }
  if (entry == nullptr) {
    if (on_probation(&source, now) >= kMaxOnProbationPerSource ||
        on_probation(nullptr, now) >= kMaxOnProbation)
      return {Verdict::kRefuse};
    // A place in the probe window: free, forgotten, a participant never proven that has stopped
    // announcing itself (Fast DDS has let it go: its lease was cut), or else one heard from but
    // never announced (nothing of Fast DDS's depends on it: random GUID prefixes cannot crowd out
    // an announcement).
    const std::uint32_t first = slot_of(prefix);
    Entry* room = nullptr;
    Entry* unannounced = nullptr;
    for (std::uint32_t i = 0; i < kProbeWindow && room == nullptr; ++i) {
      Entry& candidate = table_[(first + i) % kTableSize];
      if (!candidate.used || now - candidate.last_seen > kForgetAfter ||
          (!candidate.proven && !active_on_probation(candidate, now)))
        room = &candidate;
      else if (!candidate.announced &&
               (unannounced == nullptr || candidate.last_seen < unannounced->last_seen))
        unannounced = &candidate;
    }
    if (room == nullptr) room = unannounced;
    if (room == nullptr) return {Verdict::kRefuse};
    *room = Entry{{}, source, now, now, true, contents.other, true};
    std::memcpy(room->prefix.data(), prefix, 12);
    entry = room;
    if (entry->proven) return {};
  }
  entry->last_seen = now;
  if (contents.lease_at == 0) return {};
  return {Verdict::kShortLease, contents.lease_at, contents.lease_little_endian};
}

}  // namespace rsg::dds::internal
