// Participant announcements under probation (src/dds/internal/spdp_admission.hpp): made-up
// participants from one source hold at most kMaxOnProbationPerSource places, a real one from
// elsewhere is admitted during their flood, and one that proves itself leaves probation.
#include "dds/internal/spdp_admission.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <memory>
#include <vector>

#include "tests/support/rtps_bytes.hpp"

// A named namespace: the unity build puts this file beside rtps_screen_test.cpp's helpers.
namespace spdp_admission_test {

using rsg::dds::internal::AnnouncementSource;
using rsg::dds::internal::kMaxOnProbation;
using rsg::dds::internal::kMaxOnProbationPerSource;
using rsg::dds::internal::kProbationLease;
using rsg::dds::internal::SpdpAdmission;
using Verdict = SpdpAdmission::Verdict;
using rsg::test::Bytes;
using rsg::test::put16;
using rsg::test::put32;

Bytes header(std::uint32_t participant) {
  Bytes out{'R', 'T', 'P', 'S', 2, 3, 0x01, 0x0f};
  for (int i = 0; i < 8; ++i) out.push_back(0x42);
  put32(out, participant);
  return out;
}

/// An SPDP DATA(p) whose only parameter is a lease of `lease_seconds`.
Bytes announcement(std::uint32_t participant, std::uint32_t lease_seconds = 0x7fffffff) {
  Bytes out = header(participant);
  Bytes body;
  put16(body, 0);
  put16(body, 16);
  for (std::uint8_t b : {0x00, 0x01, 0x00, 0xc7, 0x00, 0x01, 0x00, 0xc2}) body.push_back(b);
  put32(body, 0);
  put32(body, 1);
  for (std::uint8_t b : {0x00, 0x03, 0x00, 0x00}) body.push_back(b);  // PL_CDR_LE
  put16(body, 0x0002);
  put16(body, 8);
  put32(body, lease_seconds);
  put32(body, 0);
  put16(body, 0x0001);
  put16(body, 0);
  out.push_back(0x15);
  out.push_back(0x05);
  put16(out, static_cast<std::uint32_t>(body.size()));
  out.insert(out.end(), body.begin(), body.end());
  return out;
}

/// A HEARTBEAT from `participant`: what a real participant sends once it has discovered rsg's.
Bytes heartbeat(std::uint32_t participant) {
  Bytes out = header(participant);
  out.push_back(0x07);
  out.push_back(0x01);
  put16(out, 28);
  for (std::uint8_t b : {0x00, 0x00, 0x03, 0xc7, 0x00, 0x00, 0x03, 0xc2}) out.push_back(b);
  put32(out, 0);
  put32(out, 1);
  put32(out, 0);
  put32(out, 1);
  put32(out, 1);
  return out;
}

AnnouncementSource source(std::uint32_t port) {
  AnnouncementSource s;
  s.address[12] = 127;
  s.address[15] = 1;
  s.port = port;
  return s;
}

SpdpAdmission::Decision admit(SpdpAdmission& admission, const Bytes& datagram, std::uint32_t port,
                              SpdpAdmission::Clock::time_point now) {
  return admission.admit(datagram.data(), static_cast<std::uint32_t>(datagram.size()), source(port), now);
}

TEST(SpdpAdmission, AFloodFromOneSourceHoldsFewPlacesAndARealParticipantIsAdmitted) {
  auto admission = std::make_unique<SpdpAdmission>();
  const auto now = SpdpAdmission::Clock::now();
  int admitted = 0;
  for (std::uint32_t fake = 0; fake < 300; ++fake)
    if (admit(*admission, announcement(1000 + fake), 40000, now).verdict != Verdict::kRefuse) ++admitted;
  EXPECT_EQ(admitted, static_cast<int>(kMaxOnProbationPerSource));
  // Re-announced: the same few pass, the rest are still refused.
  admitted = 0;
  for (std::uint32_t fake = 0; fake < 300; ++fake)
    if (admit(*admission, announcement(1000 + fake), 40000, now).verdict != Verdict::kRefuse) ++admitted;
  EXPECT_EQ(admitted, static_cast<int>(kMaxOnProbationPerSource));
  // A real participant, from its own socket: admitted with its lease cut, then proven.
  const auto first = admit(*admission, announcement(7, 20), 51000, now);
  EXPECT_EQ(first.verdict, Verdict::kShortLease);
  EXPECT_GT(first.lease_at, 20u);
  EXPECT_EQ(admit(*admission, heartbeat(7), 51000, now).verdict, Verdict::kPass);
  EXPECT_EQ(admit(*admission, announcement(7, 20), 51000, now).verdict, Verdict::kPass);
}

TEST(SpdpAdmission, ManySourcesAreBoundedInAll) {
  auto admission = std::make_unique<SpdpAdmission>();
  const auto now = SpdpAdmission::Clock::now();
  std::uint32_t admitted = 0;
  for (std::uint32_t fake = 0; fake < 1000; ++fake)
    if (admit(*admission, announcement(2000 + fake), 30000 + fake, now).verdict != Verdict::kRefuse)
      ++admitted;
  EXPECT_LE(admitted, kMaxOnProbation);
  EXPECT_GT(admitted, kMaxOnProbation / 2);
  // Once they stop announcing themselves, their places are free again.
  const auto later = now + kProbationLease + std::chrono::seconds(1);
  EXPECT_NE(admit(*admission, announcement(9), 52000, later).verdict, Verdict::kRefuse);
}

TEST(SpdpAdmission, ParticipantsHeardFromFirstThroughOtherTrafficAreProven) {
  auto admission = std::make_unique<SpdpAdmission>();
  const auto now = SpdpAdmission::Clock::now();
  EXPECT_EQ(admit(*admission, heartbeat(11), 53000, now).verdict, Verdict::kPass);
  EXPECT_EQ(admit(*admission, announcement(11), 53000, now).verdict, Verdict::kPass);
}

}  // namespace spdp_admission_test
