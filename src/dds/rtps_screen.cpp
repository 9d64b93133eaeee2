#include "dds/internal/rtps_screen.hpp"

#include <cstring>
#include <optional>

#include "dds/internal/rtps_ids.hpp"

namespace rsg::dds::internal {
namespace {

using Reason = RtpsScreenReason;

/// Little- or big-endian reads within a bounded span: every read is checked by its caller's
/// length test first, so none of these can see past the span.
class Span {
 public:
  Span(const std::uint8_t* data, std::uint32_t size, bool little_endian) noexcept
      : data_(data), size_(size), little_(little_endian) {}

  std::uint32_t size() const noexcept { return size_; }
  const std::uint8_t* data() const noexcept { return data_; }
  bool little_endian() const noexcept { return little_; }
  std::uint8_t u8(std::uint32_t at) const noexcept { return data_[at]; }
  std::uint16_t u16(std::uint32_t at) const noexcept {
    return little_ ? static_cast<std::uint16_t>(data_[at] | data_[at + 1] << 8)
                   : static_cast<std::uint16_t>(data_[at] << 8 | data_[at + 1]);
  }
  std::uint32_t u32(std::uint32_t at) const noexcept {
    const std::uint32_t b0 = data_[at], b1 = data_[at + 1], b2 = data_[at + 2], b3 = data_[at + 3];
    return little_ ? b0 | b1 << 8 | b2 << 16 | b3 << 24 : b3 | b2 << 8 | b1 << 16 | b0 << 24;
  }
  std::int32_t i32(std::uint32_t at) const noexcept { return static_cast<std::int32_t>(u32(at)); }
  /// An RTPS SequenceNumber_t: high (signed) then low.
  std::int64_t sequence(std::uint32_t at) const noexcept {
    return static_cast<std::int64_t>(static_cast<std::uint64_t>(u32(at)) << 32 | u32(at + 4));
  }
  std::uint32_t entity(std::uint32_t at) const noexcept {  // entity ids are octets, never swapped
    return std::uint32_t{data_[at]} << 24 | std::uint32_t{data_[at + 1]} << 16 |
           std::uint32_t{data_[at + 2]} << 8 | data_[at + 3];
  }
  Span sub(std::uint32_t at, std::uint32_t size) const noexcept { return {data_ + at, size, little_}; }

 private:
  const std::uint8_t* data_;
  std::uint32_t size_;
  bool little_;
};

constexpr std::uint32_t align4(std::uint32_t n) noexcept { return (n + 3u) & ~3u; }

// ---- The content of parameters and of built-in samples ----

/// A CDR string at `at` (length with its NUL, then the characters), as Fast DDS's fixed readers
/// take it: the length within the span and, when not empty, a NUL last. Returns where the next
/// element starts (aligned to 4), or nothing.
std::optional<std::uint32_t> skip_string(const Span& span, std::uint32_t at) noexcept {
  if (span.size() < 4 || at > span.size() - 4) return std::nullopt;
  const std::uint32_t length = span.u32(at);
  at += 4;
  if (length > span.size() - at) return std::nullopt;
  if (length > 0 && span.u8(at + length - 1) != 0) return std::nullopt;
  const std::uint32_t next = align4(at + length);
  return next <= span.size() ? next : span.size();
}

/// A sequence<octet> at `at`: the length within the span.
std::optional<std::uint32_t> skip_octets(const Span& span, std::uint32_t at) noexcept {
  if (span.size() < 4 || at > span.size() - 4) return std::nullopt;
  const std::uint32_t length = span.u32(at);
  at += 4;
  if (length > span.size() - at) return std::nullopt;
  const std::uint32_t next = align4(at + length);
  return next <= span.size() ? next : span.size();
}

/// A count read from the wire, bounded by what the elements that follow must occupy at least.
std::optional<std::uint32_t> bounded_count(const Span& span, std::uint32_t at,
                                           std::uint32_t min_element_bytes) noexcept {
  if (span.size() < 4 || at > span.size() - 4) return std::nullopt;
  const std::uint32_t count = span.u32(at);
  if (count > (span.size() - at - 4) / min_element_bytes) return std::nullopt;
  return count;
}

/// A sequence of strings (partitions, a content filter's parameters).
std::optional<std::uint32_t> skip_strings(const Span& span, std::uint32_t at) noexcept {
  const auto count = bounded_count(span, at, 4);
  if (!count) return std::nullopt;
  std::optional<std::uint32_t> next = at + 4;
  for (std::uint32_t i = 0; i < *count && next; ++i) next = skip_string(span, *next);
  return next;
}

/// A sequence of {string, string} (a property list) or, with `binary`, {string, sequence<octet>}.
std::optional<std::uint32_t> skip_properties(const Span& span, std::uint32_t at, bool binary) noexcept {
  const auto count = bounded_count(span, at, 8);
  if (!count) return std::nullopt;
  std::optional<std::uint32_t> next = at + 4;
  for (std::uint32_t i = 0; i < *count && next; ++i) {
    next = skip_string(span, *next);
    if (next) next = binary ? skip_octets(span, *next) : skip_string(span, *next);
  }
  return next;
}

/// A DDS Security DataHolder (a token): class id, properties, binary properties.
std::optional<std::uint32_t> skip_data_holder(const Span& span, std::uint32_t at) noexcept {
  auto next = skip_string(span, at);
  if (next) next = skip_properties(span, *next, false);
  if (next) next = skip_properties(span, *next, true);
  return next;
}

/// A Duration_t: seconds (signed) and a binary fraction; a negative one is none Fast DDS sends,
/// other than infinite (0x7fffffff / 0xffffffff) and the reserved "invalid" (-1 / 0xffffffff).
bool duration_valid(const Span& span, std::uint32_t at) noexcept {
  if (span.size() < 8 || at > span.size() - 8) return false;
  const std::int32_t seconds = span.i32(at);
  return seconds >= 0 || (seconds == -1 && span.u32(at + 4) == 0xffffffffu);
}

/// An XCDR2 DHEADER at `at` whose length lies within the span; returns where its content ends.
std::optional<std::uint32_t> skip_dheader(const Span& span, std::uint32_t at) noexcept {
  if (span.size() < 4 || at > span.size() - 4) return std::nullopt;
  const std::uint32_t length = span.u32(at);
  if (length > span.size() - at - 4) return std::nullopt;
  return at + 4 + length;
}

/// PID_TYPE_INFORMATION: XTypes 1.3's TypeInformation, a mutable struct in XCDR2: a DHEADER, then
/// members each with an EMHEADER whose length code gives its size (directly, or through the NEXTINT
/// that follows); every member within the DHEADER (CVE-2026-49863).
bool type_information_valid(const Span& value) noexcept {
  const auto end = skip_dheader(value, 0);
  if (!end) return false;
  std::uint64_t at = 4;
  while (at < *end) {
    if (*end - at < 4) return false;
    const std::uint32_t length_code = (value.u32(static_cast<std::uint32_t>(at)) >> 28) & 0x7u;
    at += 4;
    std::uint64_t size = std::uint64_t{1} << length_code;  // 1, 2, 4 or 8 bytes
    if (length_code >= 4) {
      if (*end - at < 4) return false;
      const std::uint64_t next = value.u32(static_cast<std::uint32_t>(at));
      size = 4 + (length_code == 6 ? 4 * next : length_code == 7 ? 8 * next : next);
    }
    if (size > *end - at) return false;
    at = (at + size + 3) & ~std::uint64_t{3};
  }
  return true;
}

/// Per-announcement locator counts, one per locator PID.
struct LocatorCounts {
  std::uint32_t unicast = 0, multicast = 0, default_unicast = 0, default_multicast = 0, meta_unicast = 0,
                meta_multicast = 0;
  bool add(std::uint16_t pid) noexcept {
    std::uint32_t* count = nullptr;
    switch (pid) {
      case kPidUnicastLocator:
        count = &unicast;
        break;
      case kPidMulticastLocator:
        count = &multicast;
        break;
      case kPidDefaultUnicastLocator:
        count = &default_unicast;
        break;
      case kPidDefaultMulticastLocator:
        count = &default_multicast;
        break;
      case kPidMetatrafficUnicastLocator:
        count = &meta_unicast;
        break;
      case kPidMetatrafficMulticastLocator:
        count = &meta_multicast;
        break;
      default:
        return true;
    }
    return ++*count <= kMaxLocatorsPerAnnouncement;
  }
};

/// The size of a standard parameter that Fast DDS reads as a fixed-size value (0: none), from
/// ParameterSerializer and QosPoliciesSerializer. Vendor-specific ids (0x8000 and up) mean different
/// things from different vendors and are left out.
constexpr std::uint32_t fixed_size(std::uint16_t pid) noexcept {
  switch (pid) {
    case kPidProtocolVersion:
    case kPidVendorId:
    case kPidDurability:
    case kPidOwnership:
    case kPidOwnershipStrength:
    case kPidDestinationOrder:
    case kPidTransportPriority:
    case kPidBuiltinEndpointSet:
    case kPidExpectsInlineQos:
    case kPidStatusInfo:
      return 4;
    case kPidLeaseDuration:
    case kPidTimeBasedFilter:
    case kPidDeadline:
    case kPidLatencyBudget:
    case kPidLifespan:
    case kPidPresentation:
    case kPidHistory:
    case kPidEndpointSecurityInfo:
    case kPidParticipantSecurityInfo:
      return 8;
    case kPidReliability:
    case kPidLiveliness:
    case kPidResourceLimits:
      return 12;
    case kPidParticipantGuid:
    case kPidEndpointGuid:
    case kPidGroupGuid:
    case kPidKeyHash:
      return 16;
    case kPidUnicastLocator:
    case kPidMulticastLocator:
    case kPidDefaultUnicastLocator:
    case kPidDefaultMulticastLocator:
    case kPidMetatrafficUnicastLocator:
    case kPidMetatrafficMulticastLocator:
      return kLocatorBytes;
    case kPidDurabilityService:
      return 28;
    default:
      return 0;
  }
}

/// The value of one parameter, as Fast DDS's fixed deserializers bound it. Parameters rsg does not
/// name here are left to Fast DDS, which reads them within their length.
std::optional<Reason> check_parameter(std::uint16_t pid, const Span& value,
                                      LocatorCounts& locators) noexcept {
  const auto whole = [&](std::optional<std::uint32_t> end) {
    return end.has_value() && *end <= value.size();
  };
  if (const std::uint32_t size = fixed_size(pid);
      size != 0 && (value.size() < size || (kExactParameterLengths && value.size() != size)))
    return Reason::kParameterValue;
  bool valid = true;
  switch (pid) {
    case kPidTopicName:
    case kPidTypeName:
    case kPidEntityName:
      // Fast DDS reads these as a string of at least its NUL.
      valid = whole(skip_string(value, 0)) && value.u32(0) > 0;
      break;
    case kPidLeaseDuration:
    case kPidTimeBasedFilter:
    case kPidDeadline:
    case kPidLatencyBudget:
    case kPidLifespan:
      valid = duration_valid(value, 0);
      break;
    case kPidReliability:
    case kPidLiveliness:
      valid = duration_valid(value, 4);  // kind, then the duration
      break;
    case kPidPartition:
      if (value.size() > kMaxAnnouncedPartitionBytes + 4) return Reason::kAnnouncedTooMuch;
      valid = whole(skip_strings(value, 0));  // CVE-2026-55063
      break;
    case kPidContentFilterProperty: {
      std::optional<std::uint32_t> next = 0;
      for (int field = 0; field < 4 && next; ++field) next = skip_string(value, *next);
      valid = next && whole(skip_strings(value, *next));
      break;
    }
    case kPidUserData:
    case kPidGroupData:  // kept whole as well, and with no data_limit of Fast DDS's
    case kPidTopicData:
      if (value.size() >= 4 && value.u32(0) > kMaxAnnouncedUserDataBytes) return Reason::kAnnouncedTooMuch;
      valid = whole(skip_octets(value, 0));
      break;
    case kPidUnicastLocator:
    case kPidMulticastLocator:
    case kPidDefaultUnicastLocator:
    case kPidDefaultMulticastLocator:
    case kPidMetatrafficUnicastLocator:
    case kPidMetatrafficMulticastLocator:
      if (!locators.add(pid)) return Reason::kTooManyLocators;
      break;
    case kPidPropertyList: {  // CVE-2026-53590
      if (value.size() > kMaxAnnouncedPropertyBytes + 4) return Reason::kAnnouncedTooMuch;
      // Properties, then (DDS Security 1.1, 7.2.1: PropertyQosPolicy) binary properties when bytes
      // are left: Fast DDS sends none, Wireshark reads them, so they must hold too.
      auto next = skip_properties(value, 0, false);
      if (next && value.size() - *next >= 4) next = skip_properties(value, *next, true);
      valid = whole(next);
      break;
    }
    case kPidIdentityToken:
    case kPidPermissionsToken:
    case kPidIdentityStatusToken:
      valid = whole(skip_data_holder(value, 0));
      break;
    case kPidDataRepresentation:  // CVE-2026-49861: a count of 0xFFFFFFFF
      valid = bounded_count(value, 0, 2).has_value();
      break;
    case kPidDataSharing:  // CVE-2026-49861, the data-sharing domains
      valid = bounded_count(value, 0, 8).has_value();
      break;
    case kPidTypeInformation:
      valid = type_information_valid(value);
      break;
    default:
      break;
  }
  return valid ? std::nullopt : std::optional<Reason>(Reason::kParameterValue);
}

/// A parameter list from `at` to the end of `span`, walked as Fast DDS walks it
/// (ParameterList::readParameterListfromCDRMsg): each parameter's length within the span, the
/// next one 4-aligned, a sentinel required. Writes where it ends (after the sentinel).
std::optional<Reason> check_parameter_list(const Span& span, std::uint32_t at, Reason framing,
                                           std::uint32_t& end) noexcept {
  LocatorCounts locators;
  for (;;) {
    if (span.size() < 4 || at > span.size() - 4) return framing;
    const std::uint16_t pid = span.u16(at);
    const std::uint16_t length = pid == kPidSentinel ? 0 : span.u16(at + 2);
    const std::uint32_t value = at + 4;
    if (length > span.size() - value) return framing;
    if (pid == kPidSentinel) {
      end = value;
      return std::nullopt;
    }
    if (auto bad = check_parameter(pid, span.sub(value, length), locators)) return bad;
    at = align4(value + length);
  }
}

/// The serialized payload of a built-in endpoint whose samples are parameter lists (SPDP, SEDP):
/// a PL_CDR_BE / PL_CDR_LE encapsulation, then the list.
std::optional<Reason> check_builtin_parameter_list(const std::uint8_t* payload, std::uint32_t size) noexcept {
  if (size < 4) return Reason::kParameterList;
  const std::uint8_t encapsulation = payload[1];  // Fast DDS reads the second octet only
  if (encapsulation != 0x02 && encapsulation != 0x03) return Reason::kParameterList;
  std::uint32_t end = 0;
  return check_parameter_list(Span(payload + 4, size - 4, encapsulation == 0x03), 0, Reason::kParameterList,
                              end);
}

/// CDR-encapsulated payloads: the two-octet identifier's second octet is odd for little endian.
std::optional<Span> cdr_body(const std::uint8_t* payload, std::uint32_t size) noexcept {
  if (size < 4) return std::nullopt;
  return Span(payload + 4, size - 4, (payload[1] & 0x01) != 0);
}

/// ParticipantMessageData (writer liveliness): GUID prefix, kind, sequence<octet>.
std::optional<Reason> check_participant_message(const std::uint8_t* payload, std::uint32_t size) noexcept {
  const auto body = cdr_body(payload, size);
  if (!body || body->size() < 16 || !skip_octets(*body, 16)) return Reason::kBuiltinPayload;
  return std::nullopt;
}

/// ParticipantGenericMessage (DDS Security's authentication handshake and key exchange): two
/// message identities, three GUIDs, a class id and a sequence of DataHolders.
std::optional<Reason> check_generic_message(const std::uint8_t* payload, std::uint32_t size) noexcept {
  const auto body = cdr_body(payload, size);
  constexpr std::uint32_t kFixed = 24 + 24 + 16 + 16 + 16;
  if (!body || body->size() < kFixed) return Reason::kBuiltinPayload;
  auto next = skip_string(*body, kFixed);
  if (!next) return Reason::kBuiltinPayload;
  const Span rest = body->sub(*next, body->size() - *next);
  const auto count = bounded_count(rest, 0, 12);
  if (!count) return Reason::kBuiltinPayload;
  next = 4;
  for (std::uint32_t i = 0; i < *count && next; ++i) next = skip_data_holder(rest, *next);
  return next ? std::nullopt : std::optional<Reason>(Reason::kBuiltinPayload);
}

// Built-in entity ids (RTPS 2.5, 9.3.1.4; DDS Security 1.1, 7.4.5 and 7.4.7).
enum class Builtin : std::uint8_t { kNone, kParameterList, kParticipantMessage, kGenericMessage, kOther };

Builtin builtin_kind(std::uint32_t entity) noexcept {
  switch (entity) {
    case 0x000100c2:
    case 0x000100c7:  // SPDP participant writer / reader
    case 0xff0101c2:
    case 0xff0101c7:  // its secure variant
    case 0x000003c2:
    case 0x000003c7:  // SEDP publications
    case 0x000004c2:
    case 0x000004c7:  // SEDP subscriptions
    case 0xff0003c2:
    case 0xff0003c7:  // secure publications
    case 0xff0004c2:
    case 0xff0004c7:  // secure subscriptions
      return Builtin::kParameterList;
    case 0x000200c2:
    case 0x000200c7:  // participant message (liveliness)
    case 0xff0200c2:
    case 0xff0200c7:  // its secure variant
      return Builtin::kParticipantMessage;
    case 0x000201c3:
    case 0x000201c4:  // participant stateless message (authentication)
    case 0xff0202c3:
    case 0xff0202c4:  // participant volatile message (key exchange)
      return Builtin::kGenericMessage;
    default:
      // Entity kinds 0xc0 to 0xcf are built-in (type lookup, vendors' own): rsg leaves their
      // payloads to Fast DDS but never takes them in fragments.
      return (entity & 0xf0u) == 0xc0u ? Builtin::kOther : Builtin::kNone;
  }
}

/// The most specific of the writer's and the reader's kinds: a DATA addressed to a built-in
/// reader from any writer id is read by that reader.
Builtin builtin_of(std::uint32_t reader, std::uint32_t writer) noexcept {
  const Builtin by_writer = builtin_kind(writer), by_reader = builtin_kind(reader);
  if (by_writer != Builtin::kNone && by_writer != Builtin::kOther) return by_writer;
  if (by_reader != Builtin::kNone && by_reader != Builtin::kOther) return by_reader;
  return by_writer != Builtin::kNone ? by_writer : by_reader;
}

std::optional<Reason> check_builtin_payload(Builtin kind, const std::uint8_t* payload,
                                            std::uint32_t size) noexcept {
  switch (kind) {
    case Builtin::kParameterList:
      return check_builtin_parameter_list(payload, size);
    case Builtin::kParticipantMessage:
      return check_participant_message(payload, size);
    case Builtin::kGenericMessage:
      return check_generic_message(payload, size);
    default:
      return std::nullopt;
  }
}

// ---- Submessages ----

/// A SequenceNumberSet or FragmentNumberSet at `at`: base (`base_bytes`), numBits at most 256 and
/// its bitmap words within the submessage. Returns where the set ends.
std::optional<std::uint32_t> skip_number_set(const Span& body, std::uint32_t at,
                                             std::uint32_t base_bytes) noexcept {
  if (body.size() < base_bytes + 4 || at > body.size() - base_bytes - 4) return std::nullopt;
  const std::uint32_t bits = body.u32(at + base_bytes);
  if (bits > 256) return std::nullopt;
  const std::uint32_t end = at + base_bytes + 4 + 4 * ((bits + 31) / 32);
  return end <= body.size() ? std::optional<std::uint32_t>(end) : std::nullopt;
}

/// Inline QoS at `at` when the Q flag is set: a parameter list without encapsulation. Writes
/// where the payload starts.
std::optional<Reason> check_inline_qos(const Span& body, std::uint8_t flags, std::uint32_t at,
                                       std::uint32_t& payload) noexcept {
  payload = at;
  if ((flags & kFlagInlineQos) == 0) return std::nullopt;
  return check_parameter_list(body, at, Reason::kInlineQos, payload);
}

std::optional<Reason> check_data(const Span& body, std::uint8_t flags) noexcept {
  // extraFlags, octetsToInlineQos, readerId, writerId, writerSN
  if (body.size() < 20) return Reason::kData;
  const std::uint16_t to_inline_qos = body.u16(2);
  if (to_inline_qos < 16 || to_inline_qos > body.size() - 4) return Reason::kData;
  if (body.sequence(12) <= 0) return Reason::kData;
  if ((flags & kFlagData) != 0 && (flags & kFlagKey) != 0) return Reason::kData;  // 8.3.7.2: not both
  std::uint32_t payload = 0;
  if (auto bad = check_inline_qos(body, flags, 4u + to_inline_qos, payload)) return bad;
  if ((flags & (kFlagData | kFlagKey)) == 0) return std::nullopt;
  const Builtin kind = builtin_of(body.entity(4), body.entity(8));
  return check_builtin_payload(kind, body.data() + payload, body.size() - payload);
}

std::optional<Reason> check_data_frag(const Span& body, std::uint8_t flags) noexcept {
  // extraFlags, octetsToInlineQos, readerId, writerId, writerSN, fragmentStartingNum,
  // fragmentsInSubmessage, fragmentSize, sampleSize
  if (body.size() < 32) return Reason::kDataFrag;
  if (builtin_of(body.entity(4), body.entity(8)) != Builtin::kNone) return Reason::kFragmentedBuiltin;
  const std::uint16_t to_inline_qos = body.u16(2);
  // CVE-2025-65865: an offset smaller than the fixed part, or past the submessage.
  if (to_inline_qos < 28 || to_inline_qos > body.size() - 4) return Reason::kDataFrag;
  if (body.sequence(12) <= 0) return Reason::kDataFrag;
  const std::uint32_t first = body.u32(20);
  const std::uint32_t in_submessage = body.u16(24);
  const std::uint32_t fragment_size = body.u16(26);
  const std::uint32_t sample_size = body.u32(28);
  if (first == 0 || in_submessage == 0 || fragment_size == 0 || sample_size == 0) return Reason::kDataFrag;
  if (sample_size > kMaxFragmentedSampleBytes) return Reason::kSampleTooLarge;
  const std::uint64_t fragments = (std::uint64_t{sample_size} + fragment_size - 1) / fragment_size;
  const std::uint64_t last = std::uint64_t{first} + in_submessage - 1;
  if (last > fragments) return Reason::kDataFrag;
  if (fragments > 1) {
    // CVE-2025-62799: Fast DDS keeps the index of the next missing fragment in each missing one, 4
    // bytes at its 4-aligned start; before 2.14.6 / 3.2.4 it reserves the sample size only, so a
    // last fragment that cannot hold that index runs past the buffer.
    if (fragment_size < 4) return Reason::kDataFrag;
    const std::uint64_t last_offset = (fragments - 1) * fragment_size;
    if (((last_offset + 3) & ~std::uint64_t{3}) + 4 > sample_size) return Reason::kDataFrag;
  }
  std::uint32_t payload = 0;
  if (auto bad = check_inline_qos(body, flags, 4u + to_inline_qos, payload)) return bad;
  // CVE-2026-22590: the bytes the fragments claim (the last one: up to the sample's end) present.
  const std::uint64_t start = (std::uint64_t{first} - 1) * fragment_size;
  const std::uint64_t end = last * fragment_size < sample_size ? last * fragment_size : sample_size;
  if (end - start > body.size() - payload) return Reason::kDataFrag;
  return std::nullopt;
}

/// A submessage of fixed layout holds exactly that: RTPS 2.5 lets a later version append fields, but
/// no DDS implementation does (the optional group fields have flags of their own, allowed for
/// by the callers), and Wireshark reads what follows as an error.
std::optional<Reason> exactly(const Span& body, std::uint32_t bytes, Reason reason) noexcept {
  return body.size() == bytes ? std::nullopt : std::optional<Reason>(reason);
}

constexpr std::uint8_t kFlagGroupInfo = 0x08;      // HEARTBEAT: RTPS 2.4's group sequence numbers follow
constexpr std::uint8_t kFlagGapExtensions = 0x06;  // GAP: filtered count, group info

std::optional<Reason> check_gap(const Span& body, std::uint8_t flags) noexcept {
  // readerId, writerId, gapStart, gapList (base, numBits, bitmap)
  const auto end = body.size() >= 28 ? skip_number_set(body, 16, 8) : std::nullopt;
  if (!end || (*end != body.size() && (flags & kFlagGapExtensions) == 0)) return Reason::kGap;
  const std::int64_t start = body.sequence(8), base = body.sequence(16);
  if (start <= 0 || base < start) return Reason::kGap;
  const bool builtin = builtin_kind(body.entity(4)) != Builtin::kNone;
  if (base - start > (builtin ? kMaxBuiltinGapRange : kMaxGapRange)) return Reason::kGap;
  return std::nullopt;
}

std::optional<Reason> check_heartbeat(const Span& body, std::uint8_t flags) noexcept {
  // readerId, writerId, firstSN, lastSN, count
  if (body.size() < 28 || (body.size() != 28 && (flags & kFlagGroupInfo) == 0)) return Reason::kHeartbeat;
  const std::int64_t first = body.sequence(8), last = body.sequence(16);
  if (first <= 0 || last < first - 1) return Reason::kHeartbeat;  // 8.3.7.5: lastSN >= firstSN - 1
  return std::nullopt;
}

std::optional<Reason> check_submessage(std::uint8_t id, std::uint8_t flags, const Span& body) noexcept {
  switch (id) {
    case kData:
      return check_data(body, flags);
    case kDataFrag:
      return check_data_frag(body, flags);
    case kGap:
      return check_gap(body, flags);
    case kHeartbeat:
      return check_heartbeat(body, flags);
    case kHeartbeatFrag:  // readerId, writerId, writerSN, lastFragmentNum, count
      if (body.size() != 24 || body.sequence(8) <= 0) return Reason::kHeartbeat;
      return std::nullopt;
    case kAckNack: {  // readerId, writerId, readerSNState, count
      const auto end = skip_number_set(body, 8, 8);
      return end ? exactly(body, *end + 4, Reason::kAckNack) : Reason::kAckNack;
    }
    case kNackFrag: {  // readerId, writerId, writerSN, fragmentNumberState, count
      const auto end = body.size() >= 16 ? skip_number_set(body, 16, 4) : std::nullopt;
      if (!end || body.sequence(8) <= 0) return Reason::kNackFrag;
      return exactly(body, *end + 4, Reason::kNackFrag);
    }
    case kInfoTimestamp:
      return exactly(body, (flags & kFlagInvalidate) != 0 ? 0 : 8, Reason::kInfo);
    case kInfoSource:  // unused, version, vendor, GUID prefix
      return exactly(body, 20, Reason::kInfo);
    case kInfoDestination:
      return exactly(body, 12, Reason::kInfo);
    case kInfoReplyIp4:
      return exactly(body, (flags & kFlagMulticast) != 0 ? 16 : 8, Reason::kInfo);
    case kInfoReply: {  // unicast locator list, and a multicast one with M
      std::uint32_t at = 0;
      for (int list = 0; list < ((flags & kFlagMulticast) != 0 ? 2 : 1); ++list) {
        const auto count = bounded_count(body.sub(at, body.size() - at), 0, kLocatorBytes);
        if (!count) return Reason::kInfo;
        at += 4 + *count * kLocatorBytes;
      }
      return exactly(body, at, Reason::kInfo);
    }
    case kPad:
    case kSecBody:
    case kSecPrefix:
    case kSecPostfix:
    case kSrtpsPrefix:
    case kSrtpsPostfix:
      return std::nullopt;  // padding, and DDS Security's: opaque until Fast DDS decrypts them
    default:
      // Vendors' own (0x80 and up) Fast DDS skips; an id RTPS does not define is none a DDS
      // implementation sends (Wireshark reads some as RTPS 2.3 drafts' APP_ACK and the like).
      return id >= 0x80 ? std::nullopt : std::optional<Reason>(Reason::kUnknownSubmessage);
  }
}

}  // namespace

RtpsScreen screen_rtps_datagram(const std::uint8_t* datagram, std::uint32_t size) noexcept {
  const auto refuse = [](std::uint32_t at, Reason reason) {
    return RtpsScreen{at, RtpsScreen::Cut::kInvalid, reason};
  };
  if (size < kHeaderBytes || std::memcmp(datagram, "RTPS", 4) != 0 || datagram[4] != 2)
    return refuse(0, Reason::kNotRtps);
  // Fast DDS reads statistics only from its own vendor's messages.
  const bool eprosima = datagram[6] == kVendorEprosima[0] && datagram[7] == kVendorEprosima[1];
  std::uint32_t at = kHeaderBytes;
  while (at < size) {
    if (size - at < kSubmessageHeaderBytes) return refuse(at, Reason::kSubmessageLength);
    const std::uint8_t id = datagram[at];
    const std::uint8_t flags = datagram[at + 1];
    const bool little_endian = (flags & kFlagEndianness) != 0;
    std::uint32_t length =
        little_endian ? datagram[at + 2] | datagram[at + 3] << 8 : datagram[at + 2] << 8 | datagram[at + 3];
    const std::uint32_t body = at + kSubmessageHeaderBytes;
    if (length > size - body) return refuse(at, Reason::kSubmessageLength);
    if (eprosima && id == kStatisticsSubmessageId) {
      const bool trailing = length == kStatisticsBodyBytes && body + length == size;
      return {at, trailing ? RtpsScreen::Cut::kTrailing : RtpsScreen::Cut::kMisplaced, Reason::kNotRtps};
    }
    // Length 0 means "to the end of the message", except for these two, which are empty.
    const bool to_end = length == 0 && id != kInfoTimestamp && id != kPad;
    if (to_end) length = size - body;
    // RTPS 2.5, 9.4.1: every submessage starts 4-aligned; Fast DDS rounds a shorter length up,
    // Wireshark does not, and the two then read different submessages from the same bytes. Only
    // the last may end unaligned.
    if (length % 4 != 0 && body + length != size) return refuse(at, Reason::kSubmessageLength);
    if (auto bad = check_submessage(id, flags, Span(datagram + body, length, little_endian)))
      return refuse(at, *bad);
    if (to_end) break;
    at = body + align4(length);
  }
  return {size, RtpsScreen::Cut::kNone, Reason::kNotRtps};
}

}  // namespace rsg::dds::internal
