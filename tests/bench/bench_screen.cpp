// What the RTPS screen and the discovery admission (src/dds/rtps_screen.cpp,
// src/dds/spdp_admission.cpp) cost per received datagram: every rsg participant runs both on each
// one before Fast DDS parses it. Figures: docs/benchmarks/rtps-screen.md.
#include <benchmark/benchmark.h>

#include <cstdint>
#include <memory>
#include <vector>

#include "dds/internal/rtps_screen.hpp"
#include "dds/internal/spdp_admission.hpp"

namespace {

using Bytes = std::vector<std::uint8_t>;

void submessage(Bytes& m, std::uint8_t id, std::uint8_t flags, const Bytes& body) {
  m.insert(m.end(),
           {id, flags, static_cast<std::uint8_t>(body.size()), static_cast<std::uint8_t>(body.size() >> 8)});
  m.insert(m.end(), body.begin(), body.end());
}

Bytes header() { return {'R', 'T', 'P', 'S', 2, 3, 0x01, 0x0f, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12}; }

/// What a reader of the gateway receives per sample: INFO_TS, the 2.1 kB state DATA, a HEARTBEAT.
Bytes state_message() {
  Bytes m = header();
  submessage(m, 0x09, 0x01, Bytes(8, 1));
  Bytes data{0, 0, 16, 0, 0, 0, 1, 7, 0, 0, 1, 2, 0, 0, 0, 0, 1, 0, 0, 0};
  data.resize(data.size() + 2140, 0x5a);
  submessage(m, 0x15, 0x05, data);
  submessage(m, 0x07, 0x01,
             {0, 0, 1, 7, 0, 0, 1, 2, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0});
  return m;
}

/// A participant announcement with a dozen parameters, as Fast DDS sends one every 3 s.
Bytes announcement() {
  Bytes list{0x00, 0x03, 0x00, 0x00};
  const auto parameter = [&list](std::uint16_t pid, Bytes value) {
    while (value.size() % 4 != 0) value.push_back(0);
    list.insert(list.end(),
                {static_cast<std::uint8_t>(pid), static_cast<std::uint8_t>(pid >> 8),
                 static_cast<std::uint8_t>(value.size()), static_cast<std::uint8_t>(value.size() >> 8)});
    list.insert(list.end(), value.begin(), value.end());
  };
  Bytes locator{1, 0, 0, 0, 0xf2, 0x1c, 0, 0};
  locator.resize(20, 0);
  locator.insert(locator.end(), {127, 0, 0, 1});
  parameter(0x0015, {2, 3});
  parameter(0x0016, {1, 0x0f});
  parameter(0x0050, Bytes(16, 0xa5));
  for (int i = 0; i < 4; ++i) parameter(0x0032, locator);
  for (int i = 0; i < 4; ++i) parameter(0x0031, locator);
  parameter(0x0002, {20, 0, 0, 0, 0, 0, 0, 0});
  parameter(0x0058, {0x3f, 0x0c, 0, 0});
  parameter(0x0062, {12, 0, 0, 0, 'r', 's', 'g', '_', 'g', 'a', 't', 'e', 'w', 'a', 'y', 0});
  list.insert(list.end(), {1, 0, 0, 0});
  Bytes data{0, 0, 16, 0, 0, 1, 0, 0xc7, 0, 1, 0, 0xc2, 0, 0, 0, 0, 1, 0, 0, 0};
  data.insert(data.end(), list.begin(), list.end());
  Bytes m = header();
  submessage(m, 0x15, 0x05, data);
  return m;
}

void BM_Screen(benchmark::State& state, const Bytes& message) {
  const auto size = static_cast<std::uint32_t>(message.size());
  for (auto _ : state) {
    const auto screen = rsg::dds::internal::screen_rtps_datagram(message.data(), size);
    benchmark::DoNotOptimize(screen);
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * message.size()));
}

void BM_ScreenAndAdmit(benchmark::State& state, const Bytes& message) {
  const auto size = static_cast<std::uint32_t>(message.size());
  auto admission = std::make_unique<rsg::dds::internal::SpdpAdmission>();
  const rsg::dds::internal::AnnouncementSource source{};
  for (auto _ : state) {
    const auto screen = rsg::dds::internal::screen_rtps_datagram(message.data(), size);
    auto decision = admission->admit(message.data(), screen.forward_bytes, source,
                                     rsg::dds::internal::SpdpAdmission::Clock::now());
    benchmark::DoNotOptimize(decision);
  }
}

}  // namespace

BENCHMARK_CAPTURE(BM_Screen, StateSample, state_message())->Name("BM_Screen_StateSample");
BENCHMARK_CAPTURE(BM_Screen, Announcement, announcement())->Name("BM_Screen_Announcement");
BENCHMARK_CAPTURE(BM_ScreenAndAdmit, StateSample, state_message())->Name("BM_ScreenAndAdmit_StateSample");
BENCHMARK_CAPTURE(BM_ScreenAndAdmit, Announcement, announcement())->Name("BM_ScreenAndAdmit_Announcement");

BENCHMARK_MAIN();
