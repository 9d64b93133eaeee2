// The RTPS screen (src/dds/internal/rtps_screen.hpp) on hand-made messages: each check passes
// what a Fast DDS peer sends and cuts what the published flaws need, from that submessage on.
#include "dds/internal/rtps_screen.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <initializer_list>
#include <string>
#include <vector>

#include "tests/support/rtps_bytes.hpp"

namespace {

using rsg::dds::RtpsScreenReason;
using rsg::dds::internal::RtpsScreen;
using rsg::dds::internal::screen_rtps_datagram;
using rsg::test::Bytes;
using rsg::test::put16;
using rsg::test::put32;

void put_sequence(Bytes& out, std::int64_t sn) {
  put32(out, static_cast<std::uint32_t>(static_cast<std::uint64_t>(sn) >> 32));
  put32(out, static_cast<std::uint32_t>(sn));
}
void put_entity(Bytes& out, std::uint32_t entity) {
  for (int shift = 24; shift >= 0; shift -= 8) out.push_back(static_cast<std::uint8_t>(entity >> shift));
}
void append(Bytes& out, const Bytes& more) { out.insert(out.end(), more.begin(), more.end()); }

Bytes header(std::uint8_t vendor_low = 0x0f) {
  Bytes out{'R', 'T', 'P', 'S', 2, 3, 0x01, vendor_low};
  for (int i = 0; i < 12; ++i) out.push_back(static_cast<std::uint8_t>(0xa0 + i));
  return out;
}

/// A little-endian submessage.
Bytes submessage(std::uint8_t id, const Bytes& body, std::uint8_t flags = 0) {
  Bytes out{id, static_cast<std::uint8_t>(flags | 0x01)};
  put16(out, static_cast<std::uint32_t>(body.size()));
  append(out, body);
  return out;
}

Bytes parameter(std::uint16_t pid, Bytes value) {
  while (value.size() % 4 != 0) value.push_back(0);
  Bytes out;
  put16(out, pid);
  put16(out, static_cast<std::uint32_t>(value.size()));
  append(out, value);
  return out;
}
Bytes u32s(std::initializer_list<std::uint32_t> values) {
  Bytes out;
  for (auto v : values) put32(out, v);
  return out;
}
Bytes cdr_string(const std::string& text, bool nul = true) {
  Bytes out;
  put32(out, static_cast<std::uint32_t>(text.size() + (nul ? 1 : 0)));
  // Byte by byte: GCC 12 at -O2 (a file compiled alone) reads insert() after put32 as a copy
  // from an empty region (-Wstringop-overread, a false positive).
  for (const char c : text) out.push_back(static_cast<std::uint8_t>(c));
  if (nul) out.push_back(0);
  while (out.size() % 4 != 0) out.push_back(0);
  return out;
}
Bytes locator(std::uint32_t port) {
  Bytes out = u32s({1, port});
  for (int i = 0; i < 12; ++i) out.push_back(0);
  append(out, Bytes{127, 0, 0, 1});
  return out;
}

constexpr std::uint32_t kSpdpWriter = 0x000100c2, kSpdpReader = 0x000100c7;
constexpr std::uint32_t kSedpPubWriter = 0x000003c2, kSedpPubReader = 0x000003c7;
constexpr std::uint32_t kUserWriter = 0x00000102, kUserReader = 0x00000107;

/// A participant announcement's parameters, as Fast DDS sends them (the common ones).
Bytes spdp_parameters(const Bytes& extra = {}) {
  Bytes list;
  append(list, parameter(0x0015, {2, 3}));                     // protocol version
  append(list, parameter(0x0016, {0x01, 0x0f}));               // vendor
  append(list, parameter(0x0050, Bytes(16, 0xa5)));            // participant GUID
  append(list, parameter(0x0032, locator(7410)));              // metatraffic unicast
  append(list, parameter(0x0031, locator(7411)));              // default unicast
  append(list, parameter(0x0002, u32s({20, 0})));              // lease duration
  append(list, parameter(0x0058, u32s({0x00000c3f})));         // builtin endpoints
  append(list, parameter(0x0062, cdr_string("rsg_gateway")));  // entity name
  append(list, parameter(0x0059, [] {                          // property list
           Bytes p = u32s({1});
           append(p, cdr_string("fastdds.application.id"));
           append(p, cdr_string("rsg"));
           return p;
         }()));
  append(list, extra);
  append(list, u32s({0x00000001}));  // sentinel
  return list;
}

/// DATA with a serialized payload from `writer` to `reader`.
Bytes data(std::uint32_t reader, std::uint32_t writer, const Bytes& payload, std::int64_t sn = 1) {
  Bytes body;
  put16(body, 0);
  put16(body, 16);
  put_entity(body, reader);
  put_entity(body, writer);
  put_sequence(body, sn);
  append(body, payload);
  return submessage(0x15, body, 0x04);
}

Bytes pl_payload(const Bytes& list) {
  Bytes payload{0x00, 0x03, 0x00, 0x00};  // PL_CDR_LE
  append(payload, list);
  return payload;
}

Bytes data_frag(std::uint32_t reader, std::uint32_t writer, std::uint32_t first, std::uint16_t count,
                std::uint16_t fragment_size, std::uint32_t sample_size, std::size_t bytes,
                std::uint16_t to_inline_qos = 28) {
  Bytes body;
  put16(body, 0);
  put16(body, to_inline_qos);
  put_entity(body, reader);
  put_entity(body, writer);
  put_sequence(body, 1);
  put32(body, first);
  put16(body, count);
  put16(body, fragment_size);
  put32(body, sample_size);
  body.resize(body.size() + bytes, 0x5a);
  return submessage(0x16, body, 0x04);
}

Bytes gap(std::uint32_t writer, std::int64_t start, std::int64_t base, std::uint32_t bits = 0) {
  Bytes body;
  put_entity(body, 0);
  put_entity(body, writer);
  put_sequence(body, start);
  put_sequence(body, base);
  put32(body, bits);
  for (std::uint32_t i = 0; i < (bits + 31) / 32; ++i) put32(body, 0);
  return submessage(0x08, body);
}

Bytes heartbeat(std::int64_t first, std::int64_t last) {
  Bytes body;
  put_entity(body, kUserReader);
  put_entity(body, kUserWriter);
  put_sequence(body, first);
  put_sequence(body, last);
  put32(body, 1);
  return submessage(0x07, body);
}

Bytes message(std::initializer_list<Bytes> submessages) {
  Bytes out = header();
  for (const auto& s : submessages) append(out, s);
  return out;
}

RtpsScreen screen(const Bytes& datagram) {
  return screen_rtps_datagram(datagram.data(), static_cast<std::uint32_t>(datagram.size()));
}

void expect_whole(const Bytes& datagram) {
  const auto result = screen(datagram);
  EXPECT_EQ(result.cut, RtpsScreen::Cut::kNone) << rsg::dds::to_string(result.reason);
  EXPECT_EQ(result.forward_bytes, datagram.size());
}

/// Cut at byte `at` for `reason`.
void expect_cut(const Bytes& datagram, std::uint32_t at, RtpsScreenReason reason) {
  const auto result = screen(datagram);
  EXPECT_EQ(result.cut, RtpsScreen::Cut::kInvalid);
  EXPECT_EQ(result.forward_bytes, at);
  EXPECT_EQ(rsg::dds::to_string(result.reason), rsg::dds::to_string(reason));
}

TEST(RtpsScreen, PassesWhatAFastDdsPeerSends) {
  expect_whole(message({data(kSpdpReader, kSpdpWriter, pl_payload(spdp_parameters()))}));
  expect_whole(
      message({data(kUserReader, kUserWriter, Bytes(2100, 1)), heartbeat(1, 1), gap(kUserWriter, 1, 5)}));
  expect_whole(message({heartbeat(1, 0)}));  // an empty history: lastSN = firstSN - 1
  // A sample in three fragments, the last one shorter and padded.
  expect_whole(message({data_frag(kUserReader, kUserWriter, 1, 2, 1000, 2500, 2000)}));
  expect_whole(message({data_frag(kUserReader, kUserWriter, 3, 1, 1000, 2500, 500 + 3)}));
  // INFO_TS, INFO_DST, PAD.
  expect_whole(
      message({submessage(0x09, u32s({1, 2})), submessage(0x0e, Bytes(12, 0)), submessage(0x01, {})}));
}

TEST(RtpsScreen, RefusesWhatIsNotRtps) {
  expect_cut(Bytes{'R', 'T', 'P', 'X', 2, 3}, 0, RtpsScreenReason::kNotRtps);
  Bytes v1 = header();
  v1[4] = 1;
  expect_cut(v1, 0, RtpsScreenReason::kNotRtps);
}

TEST(RtpsScreen, CutsASubmessageThatRunsPastTheMessageAndKeepsWhatCameBefore) {
  Bytes datagram = message({heartbeat(1, 3)});
  const auto at = static_cast<std::uint32_t>(datagram.size());
  append(datagram, Bytes{0x07, 0x01, 200, 0, 1, 2, 3});
  expect_cut(datagram, at, RtpsScreenReason::kSubmessageLength);
}

TEST(RtpsScreen, StatisticsSubmessagesAsBefore) {
  const Bytes trailing = message({heartbeat(1, 1), submessage(0x80, Bytes(56, 0))});
  EXPECT_EQ(screen(trailing).cut, RtpsScreen::Cut::kTrailing);
  const Bytes misplaced = message({submessage(0x80, Bytes(56, 0)), submessage(0x01, {})});
  EXPECT_EQ(screen(misplaced).cut, RtpsScreen::Cut::kMisplaced);
  EXPECT_EQ(screen(misplaced).forward_bytes, 20u);
}

// CVE-2025-62799: the last fragment cannot hold the 4-byte index unfixed Fast DDS writes there.
TEST(RtpsScreen, DataFragWhoseLastFragmentRunsPastTheSample) {
  expect_cut(message({data_frag(kUserReader, kUserWriter, 1, 1, 1000, 1002, 1000)}), 20,
             RtpsScreenReason::kDataFrag);
  expect_cut(message({data_frag(kUserReader, kUserWriter, 1, 1, 2, 100, 2)}), 20,
             RtpsScreenReason::kDataFrag);
  // Fragments beyond ceil(sampleSize / fragmentSize), and fragment number 0.
  expect_cut(message({data_frag(kUserReader, kUserWriter, 3, 2, 1000, 2500, 2000)}), 20,
             RtpsScreenReason::kDataFrag);
  expect_cut(message({data_frag(kUserReader, kUserWriter, 0, 1, 1000, 2500, 1000)}), 20,
             RtpsScreenReason::kDataFrag);
}

// CVE-2025-65865: octetsToInlineQos that makes the payload's length underflow.
TEST(RtpsScreen, DataFragWithAnOffsetPastItsSubmessage) {
  expect_cut(message({data_frag(kUserReader, kUserWriter, 1, 1, 1000, 2500, 8, 60)}), 20,
             RtpsScreenReason::kDataFrag);
  expect_cut(message({data_frag(kUserReader, kUserWriter, 1, 1, 1000, 2500, 1000, 12)}), 20,
             RtpsScreenReason::kDataFrag);
}

// CVE-2026-22590: a fragment claims more bytes than it carries, the last one too.
TEST(RtpsScreen, DataFragThatCarriesFewerBytesThanItClaims) {
  expect_cut(message({data_frag(kUserReader, kUserWriter, 1, 2, 1000, 2500, 1000)}), 20,
             RtpsScreenReason::kDataFrag);
  expect_cut(message({data_frag(kUserReader, kUserWriter, 3, 1, 1000, 2500, 4)}), 20,
             RtpsScreenReason::kDataFrag);
}

TEST(RtpsScreen, FragmentedBuiltinAndHugeSamples) {
  expect_cut(message({data_frag(kSpdpReader, kSpdpWriter, 1, 1, 1000, 2500, 1000)}), 20,
             RtpsScreenReason::kFragmentedBuiltin);
  expect_cut(message({data_frag(kUserReader, kUserWriter, 1, 1, 60000, 0xffffff00, 60000)}), 20,
             RtpsScreenReason::kSampleTooLarge);
}

// CVE-2025-64438: a GAP of 2^32 sequence numbers.
TEST(RtpsScreen, GapRanges) {
  expect_cut(message({gap(kSedpPubWriter, 1, std::int64_t{1} << 32)}), 20, RtpsScreenReason::kGap);
  expect_cut(message({gap(kUserWriter, 1, std::int64_t{1} << 32)}), 20, RtpsScreenReason::kGap);
  expect_cut(message({gap(kUserWriter, 5, 4)}), 20, RtpsScreenReason::kGap);
  expect_cut(message({gap(kUserWriter, 0, 4)}), 20, RtpsScreenReason::kGap);
  expect_cut(message({gap(kUserWriter, 1, 2, 257)}), 20, RtpsScreenReason::kGap);
  expect_whole(message({gap(kUserWriter, 1, 1000, 256)}));
  expect_whole(message({gap(kUserWriter, 1, 1 + (std::int64_t{1} << 20))}));
}

TEST(RtpsScreen, HeartbeatsAndAckNacks) {
  expect_cut(message({heartbeat(0, 3)}), 20, RtpsScreenReason::kHeartbeat);
  expect_cut(message({heartbeat(5, 3)}), 20, RtpsScreenReason::kHeartbeat);
  Bytes acknack;
  put_entity(acknack, kUserReader);
  put_entity(acknack, kUserWriter);
  put_sequence(acknack, 1);
  put32(acknack, 300);  // numBits over 256
  put32(acknack, 1);
  expect_cut(message({submessage(0x06, acknack)}), 20, RtpsScreenReason::kAckNack);
}

/// An SPDP announcement with `extra` parameters, cut for `reason`.
void expect_spdp_cut(const Bytes& extra, RtpsScreenReason reason) {
  expect_cut(message({data(kSpdpReader, kSpdpWriter, pl_payload(spdp_parameters(extra)))}), 20, reason);
}

// CVE-2026-49861: element counts the parameter cannot hold.
TEST(RtpsScreen, ParameterCountsBoundedByTheirLength) {
  expect_spdp_cut(parameter(0x0073, u32s({0xffffffff})), RtpsScreenReason::kParameterValue);
  expect_spdp_cut(parameter(0x8006, u32s({0xffffffff, 0, 0})), RtpsScreenReason::kParameterValue);
  expect_spdp_cut(parameter(0x0059, u32s({0x10000000})), RtpsScreenReason::kParameterValue);
  expect_spdp_cut(parameter(0x0029, u32s({0x40000000})), RtpsScreenReason::kParameterValue);
  // A data representation list that fits passes.
  expect_whole(message(
      {data(kSpdpReader, kSpdpWriter, pl_payload(spdp_parameters(parameter(0x0073, {1, 0, 0, 0, 0, 0}))))}));
}

TEST(RtpsScreen, StringsDurationsAndLocators) {
  expect_spdp_cut(parameter(0x0062, cdr_string("no terminator", false)), RtpsScreenReason::kParameterValue);
  expect_spdp_cut(parameter(0x0005, u32s({0})), RtpsScreenReason::kParameterValue);
  expect_spdp_cut(parameter(0x0029,
                            [] {
                              Bytes p = u32s({1});
                              append(p, cdr_string("robot1", false));
                              return p;
                            }()),
                  RtpsScreenReason::kParameterValue);  // CVE-2026-55063
  expect_spdp_cut(parameter(0x0023, u32s({0x80000000u, 0})), RtpsScreenReason::kParameterValue);
  expect_spdp_cut(parameter(0x0031, Bytes(8, 0)), RtpsScreenReason::kParameterValue);
  Bytes many;
  for (int i = 0; i < 200; ++i) append(many, parameter(0x002f, locator(40000 + i)));
  expect_spdp_cut(many, RtpsScreenReason::kTooManyLocators);
  // Infinite durations pass.
  expect_whole(
      message({data(kSpdpReader, kSpdpWriter,
                    pl_payload(spdp_parameters(parameter(0x0023, u32s({0x7fffffff, 0xffffffff})))))}));
}

// Fast DDS keeps what an announcement carries, and keeps a sample it refuses for its size: the
// screen refuses user data, partitions and properties over rsg's data_limits first.
TEST(RtpsScreen, AnnouncementsThatCarryMoreThanAParticipantKeeps) {
  using rsg::dds::internal::kMaxAnnouncedUserDataBytes;
  const auto octets = [](std::uint32_t size) {
    Bytes value = u32s({size});
    value.resize(4 + size, 0xab);
    return value;
  };
  // ROS 2's type hash, and user data at the limit, pass.
  expect_whole(
      message({data(kSpdpReader, kSpdpWriter,
                    pl_payload(spdp_parameters(parameter(0x002c, cdr_string(std::string(80, 'h'))))))}));
  expect_whole(
      message({data(kSpdpReader, kSpdpWriter,
                    pl_payload(spdp_parameters(parameter(0x002c, octets(kMaxAnnouncedUserDataBytes)))))}));
  for (const std::uint16_t pid : {0x002c, 0x002d, 0x002e})  // user, group, topic data
    expect_spdp_cut(parameter(pid, octets(kMaxAnnouncedUserDataBytes + 1)),
                    RtpsScreenReason::kAnnouncedTooMuch);
  Bytes partitions = u32s({200});
  for (int i = 0; i < 200; ++i) append(partitions, cdr_string("partition"));
  expect_spdp_cut(parameter(0x0029, partitions), RtpsScreenReason::kAnnouncedTooMuch);
  Bytes properties = u32s({100});
  for (int i = 0; i < 100; ++i) {
    append(properties, cdr_string("fastdds.property"));
    append(properties, cdr_string("value"));
  }
  expect_spdp_cut(parameter(0x0059, properties), RtpsScreenReason::kAnnouncedTooMuch);
}

// Fast DDS 2.9 refuses a fixed-size parameter of another length, 2.14 and 3.x a shorter one, and
// keeps the announcement it could not read: the screen refuses it first.
TEST(RtpsScreen, FixedSizeParametersOfAnotherLength) {
  expect_spdp_cut(parameter(0x001a, u32s({2, 0})),
                  RtpsScreenReason::kParameterValue);  // reliability: 8 of 12
  expect_spdp_cut(parameter(0x005a, Bytes(12, 1)),
                  RtpsScreenReason::kParameterValue);  // endpoint GUID: 12 of 16
  expect_spdp_cut(parameter(0x001e, Bytes(24, 0)), RtpsScreenReason::kParameterValue);  // durability service
  const Bytes longer = parameter(0x001d, u32s({1, 0}));                                 // durability: 8 of 4
  if (rsg::dds::internal::kExactParameterLengths)
    expect_spdp_cut(longer, RtpsScreenReason::kParameterValue);
  else
    expect_whole(message({data(kSpdpReader, kSpdpWriter, pl_payload(spdp_parameters(longer)))}));
  // The sizes Fast DDS sends pass.
  Bytes qos;
  append(qos, parameter(0x001d, u32s({1})));           // durability
  append(qos, parameter(0x001a, u32s({2, 0, 1000})));  // reliability
  append(qos, parameter(0x001e, Bytes(28, 0)));        // durability service
  append(qos, parameter(0x0021, Bytes(8, 0)));         // presentation
  append(qos, parameter(0x0040, u32s({0, 1})));        // history
  append(qos, parameter(0x005a, Bytes(16, 0xa5)));     // endpoint GUID
  append(qos, parameter(0x1004, u32s({0, 0})));        // endpoint security info
  expect_whole(message({data(kSpdpReader, kSpdpWriter, pl_payload(spdp_parameters(qos)))}));
}

Bytes from_hex(const std::string& hex) {
  Bytes out;
  for (std::size_t i = 0; i + 1 < hex.size(); i += 2)
    out.push_back(static_cast<std::uint8_t>(std::stoi(hex.substr(i, 2), nullptr, 16)));
  return out;
}

// PID_TYPE_INFORMATION as a ROS 2 Kilted publisher (Fast DDS 3.2.2) announces it: a mutable
// XCDR2 struct, a DHEADER and two members with EMHEADERs.
TEST(RtpsScreen, TypeInformation) {
  const std::string kilted =
      "580000000110005024000000140000"
      "00f1fd2717da51821d97faaea3821def002c000000ffffffff0400000000000000"
      "021000502400000014000000f2b757c643cd8a4af3894fe45024370070000000ffffffff0400000000000000";
  expect_whole(message(
      {data(kSpdpReader, kSedpPubWriter, pl_payload(spdp_parameters(parameter(0x0075, from_hex(kilted)))))}));
  Bytes lying = from_hex(kilted);
  lying[8] = 0x60;  // the first member's NEXTINT past the DHEADER
  expect_spdp_cut(parameter(0x0075, lying), RtpsScreenReason::kParameterValue);
  Bytes outer = from_hex(kilted);
  outer[0] = 0x90;  // the DHEADER past the parameter
  expect_spdp_cut(parameter(0x0075, outer), RtpsScreenReason::kParameterValue);
}

TEST(RtpsScreen, ParameterListFraming) {
  Bytes no_sentinel = spdp_parameters();
  no_sentinel.erase(no_sentinel.end() - 4, no_sentinel.end());
  expect_cut(message({data(kSpdpReader, kSpdpWriter, pl_payload(no_sentinel))}), 20,
             RtpsScreenReason::kParameterList);
  Bytes cdr{0x00, 0x01, 0x00, 0x00};  // CDR_LE, not a parameter list
  append(cdr, spdp_parameters());
  expect_cut(message({data(kSpdpReader, kSpdpWriter, cdr)}), 20, RtpsScreenReason::kParameterList);
  // A user writer's DATA to the SPDP reader is read by it: checked the same way.
  expect_cut(message({data(kSpdpReader, kUserWriter, pl_payload(no_sentinel))}), 20,
             RtpsScreenReason::kParameterList);
  // A user sample is not a parameter list: left alone.
  expect_whole(message({data(kUserReader, kUserWriter, pl_payload(no_sentinel))}));
}

TEST(RtpsScreen, CutKeepsTheValidSubmessagesBefore) {
  const Bytes first = data(kUserReader, kUserWriter, Bytes(100, 1));
  const Bytes datagram = message({first, gap(kUserWriter, 1, std::int64_t{1} << 40), heartbeat(1, 1)});
  expect_cut(datagram, static_cast<std::uint32_t>(20 + first.size()), RtpsScreenReason::kGap);
}

}  // namespace
