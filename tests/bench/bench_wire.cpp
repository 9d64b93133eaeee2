// Wire codec costs against the floor every receiver pays: touching the bytes (memcpy) and checking
// the CRC. Names are BM_<operation>_<frame>; run_bench.sh reports each one as a ratio to
// BM_Crc32Isal_<frame>, the CRC alone on the same frame.
//
//   Full    every field: 2137 bytes, the frame the gateway normally receives
//   Joints  tau_J, q, dq and time: 190 bytes, a typical small selection
#include <benchmark/benchmark.h>
#include <zlib.h>

#include <array>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <span>
#include <vector>

#include "rsg/wire/crc32.hpp"
#include "rsg/wire/error_flags.hpp"
#include "rsg/wire/frame.hpp"
#include "rsg/wire/frame_codec.hpp"
#include "rsg/wire/state_values.hpp"

namespace {

/// A valid frame carrying `selection`, and the values it was encoded from.
class SampleFrame {
 public:
  explicit SampleFrame(const rsg::wire::Selection& selection) {
    values_.packet_number = 5;
    values_.selection = selection;
    for (const rsg::wire::FieldInfo& field : rsg::wire::kFields) fill(field);
    bytes_.resize(rsg::wire::kMaxFrameBytes);
    const rsg::wire::EncodeResult result = rsg::wire::encode(
        values_.packet_number, selection, values_.storage(), rsg::wire::StateValues::layout(), bytes_);
    if (!result) std::abort();  // a benchmark of a frame that does not encode would measure nothing
    bytes_.resize(result.size);
  }

  const rsg::wire::StateValues& values() const { return values_; }
  std::span<const std::uint8_t> bytes() const { return bytes_; }
  /// The bytes the trailer's CRC covers: header and data.
  std::span<const std::uint8_t> crc_covered() const {
    return bytes().first(bytes_.size() - rsg::wire::kCrcBytes);
  }

 private:
  void fill(const rsg::wire::FieldInfo& field) {
    switch (field.type) {
      case rsg::wire::ElementType::kFloat64: {
        double element = field.index;
        for (double& value : values_.doubles(field.id())) value = element += 0.125;
        break;
      }
      case rsg::wire::ElementType::kErrorSet:
        values_.set_integer(field.id(), 0x15'5555'5555ULL >> field.index % 2);  // every other flag
        break;
      case rsg::wire::ElementType::kUInt8:
        values_.set_integer(field.id(), rsg::wire::kMaxRobotMode);
        break;
      case rsg::wire::ElementType::kUInt64:
        values_.set_integer(field.id(), 1'234'567'890'123ULL);
        break;
    }
  }

  rsg::wire::StateValues values_;
  std::vector<std::uint8_t> bytes_;
};

rsg::wire::Selection joints_selection() {
  rsg::wire::Selection selection;
  for (const rsg::wire::Field field :
       {rsg::wire::Field::tau_J, rsg::wire::Field::q, rsg::wire::Field::dq, rsg::wire::Field::time})
    selection.add(field);
  return selection;
}

const SampleFrame& full_frame() {
  static const SampleFrame frame(rsg::wire::Selection::all());
  return frame;
}

const SampleFrame& joints_frame() {
  static const SampleFrame frame(joints_selection());
  return frame;
}

void count_bytes(benchmark::State& state, std::size_t bytes_per_iteration) {
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * bytes_per_iteration));
}

void BM_Memcpy(benchmark::State& state, const SampleFrame& frame) {
  std::array<std::uint8_t, rsg::wire::kMaxFrameBytes> copy{};
  for (auto _ : state) {
    benchmark::DoNotOptimize(frame.bytes().data());
    std::memcpy(copy.data(), frame.bytes().data(), frame.bytes().size());
    benchmark::ClobberMemory();
  }
  count_bytes(state, frame.bytes().size());
}

void BM_Crc32Isal(benchmark::State& state, const SampleFrame& frame) {
  for (auto _ : state) benchmark::DoNotOptimize(rsg::wire::crc32(frame.crc_covered()));
  count_bytes(state, frame.crc_covered().size());
}

void BM_Crc32Zlib(benchmark::State& state, const SampleFrame& frame) {
  const auto covered = frame.crc_covered();
  for (auto _ : state)
    benchmark::DoNotOptimize(::crc32(0, covered.data(), static_cast<uInt>(covered.size())));
  count_bytes(state, covered.size());
}

/// Validation alone: what a receiver that only counts frames pays.
void BM_DecodeValidateOnly(benchmark::State& state, const SampleFrame& frame) {
  for (auto _ : state) {
    const rsg::wire::DecodeResult result = rsg::wire::decode(frame.bytes());
    benchmark::DoNotOptimize(&result);
  }
  count_bytes(state, frame.bytes().size());
}

/// What the gateway does per datagram: validate and copy every field into the sample, in one pass.
void BM_Decode(benchmark::State& state, const SampleFrame& frame) {
  rsg::wire::StateValues values;
  rsg::wire::FrameCodec codec(rsg::wire::StateValues::layout());
  for (auto _ : state) {
    const rsg::wire::DecodeResult result = codec.decode(frame.bytes(), values.storage());
    if (!result) {
      state.SkipWithError("the sample frame does not decode");
      break;
    }
    values.packet_number = result.frame().packet_number();
    values.selection = result.frame().selection();
    benchmark::DoNotOptimize(values.storage());
    benchmark::ClobberMemory();
  }
  count_bytes(state, frame.bytes().size());
}

/// BM_Decode with frame and struct at the worst places found: where a 64-byte access would straddle
/// a page boundary (masked accesses there cost ~160 ns each on AMD Zen 4 unless avoided). Cycles
/// through 8 placements; each iteration decodes one frame.
void BM_DecodeAtPageEdges(benchmark::State& state, const SampleFrame& frame) {
  constexpr std::size_t kPage = 4096;
  std::vector<std::byte> arena(20 * kPage);
  const auto page = [&](std::size_t n) {
    const auto address = reinterpret_cast<std::uintptr_t>(arena.data());
    return arena.data() + (kPage - address % kPage) % kPage + n * kPage;
  };
  std::array<std::uint8_t*, 8> frames{};
  std::array<void*, 8> structs{};
  for (std::size_t i = 0; i < frames.size(); ++i) {
    frames[i] = reinterpret_cast<std::uint8_t*>(page(i)) + kPage - 8 * (i + 1);  // header at a page end
    std::memcpy(frames[i], frame.bytes().data(), frame.bytes().size());
    structs[i] = page(10 + i) - 8 * i;  // struct start just before a page boundary
  }
  rsg::wire::FrameCodec codec(rsg::wire::StateValues::layout());
  std::size_t next = 0;
  for (auto _ : state) {
    const std::size_t i = next++ % frames.size();
    const rsg::wire::DecodeResult result = codec.decode({frames[i], frame.bytes().size()}, structs[i]);
    if (!result) {
      state.SkipWithError("the sample frame does not decode");
      break;
    }
    benchmark::ClobberMemory();
  }
  count_bytes(state, frame.bytes().size());
}

/// BM_Decode with the frame at a chosen offset from a 64-byte boundary. The stitched kernel loads
/// 64-byte chunks that end where the frame's CRC-covered bytes end, so they start `padding` bytes
/// before the frame (43 for a full frame): with the frame 64-byte aligned every load straddles two
/// cache lines, with the frame at `padding` past a boundary none does. What that costs shows on
/// Intel, where a straddling 64-byte load takes two load slots (docs/benchmarks/wire.md).
void BM_DecodeFrameAt(benchmark::State& state, const SampleFrame& frame, std::size_t offset) {
  constexpr std::size_t kLine = 64;
  std::vector<std::uint8_t> buffer(frame.bytes().size() + 2 * kLine);
  const auto address = reinterpret_cast<std::uintptr_t>(buffer.data());
  std::uint8_t* placed = buffer.data() + (kLine - address % kLine) % kLine + offset % kLine;
  std::memcpy(placed, frame.bytes().data(), frame.bytes().size());
  rsg::wire::StateValues values;
  rsg::wire::FrameCodec codec(rsg::wire::StateValues::layout());
  for (auto _ : state) {
    const rsg::wire::DecodeResult result = codec.decode({placed, frame.bytes().size()}, values.storage());
    if (!result) {
      state.SkipWithError("the sample frame does not decode");
      break;
    }
    benchmark::DoNotOptimize(values.storage());
    benchmark::ClobberMemory();
  }
  count_bytes(state, frame.bytes().size());
}

/// Bytes the kernel puts before the frame so that its last chunk ends with the CRC-covered bytes.
std::size_t head_padding(const SampleFrame& frame) { return (64 - frame.crc_covered().size() % 64) % 64; }

/// The same in two passes, `decode` then `copy_fields`: what stitching the copy into the CRC saves.
void BM_DecodeThenCopy(benchmark::State& state, const SampleFrame& frame) {
  rsg::wire::StateValues values;
  for (auto _ : state) {
    const rsg::wire::DecodeResult result = rsg::wire::decode(frame.bytes());
    if (!result) {
      state.SkipWithError("the sample frame does not decode");
      break;
    }
    values.assign(result.frame());
    benchmark::DoNotOptimize(values.storage());
    benchmark::ClobberMemory();
  }
  count_bytes(state, frame.bytes().size());
}

void BM_Encode(benchmark::State& state, const SampleFrame& frame) {
  const rsg::wire::StateValues& values = frame.values();
  rsg::wire::FrameCodec codec(rsg::wire::StateValues::layout());
  std::array<std::uint8_t, rsg::wire::kMaxFrameBytes> out{};
  for (auto _ : state) {
    const rsg::wire::EncodeResult result =
        codec.encode(values.packet_number, values.selection, values.storage(), out);
    benchmark::DoNotOptimize(&result);
    benchmark::ClobberMemory();
  }
  count_bytes(state, frame.bytes().size());
}

}  // namespace

BENCHMARK_CAPTURE(BM_Memcpy, Full, full_frame())->Name("BM_Memcpy_Full");
BENCHMARK_CAPTURE(BM_Crc32Isal, Full, full_frame())->Name("BM_Crc32Isal_Full");
BENCHMARK_CAPTURE(BM_Crc32Zlib, Full, full_frame())->Name("BM_Crc32Zlib_Full");
BENCHMARK_CAPTURE(BM_DecodeValidateOnly, Full, full_frame())->Name("BM_DecodeValidateOnly_Full");
BENCHMARK_CAPTURE(BM_Decode, Full, full_frame())->Name("BM_Decode_Full");
BENCHMARK_CAPTURE(BM_DecodeThenCopy, Full, full_frame())->Name("BM_DecodeThenCopy_Full");
BENCHMARK_CAPTURE(BM_DecodeAtPageEdges, Full, full_frame())->Name("BM_DecodeAtPageEdges_Full");
BENCHMARK_CAPTURE(BM_DecodeFrameAt, LineAligned, full_frame(), 0)->Name("BM_DecodeFrameLineAligned_Full");
BENCHMARK_CAPTURE(BM_DecodeFrameAt, ChunksAligned, full_frame(), head_padding(full_frame()))
    ->Name("BM_DecodeChunksLineAligned_Full");
BENCHMARK_CAPTURE(BM_Encode, Full, full_frame())->Name("BM_Encode_Full");

BENCHMARK_CAPTURE(BM_Crc32Isal, Joints, joints_frame())->Name("BM_Crc32Isal_Joints");
BENCHMARK_CAPTURE(BM_Decode, Joints, joints_frame())->Name("BM_Decode_Joints");
BENCHMARK_CAPTURE(BM_Encode, Joints, joints_frame())->Name("BM_Encode_Joints");

BENCHMARK_MAIN();
