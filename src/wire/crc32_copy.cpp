#include "wire/internal/crc32_copy.hpp"

#include <immintrin.h>

#include <algorithm>
#include <cstring>

#include "rsg/wire/crc32.hpp"

// The stitched kernel is compiled for AVX-512 and runs only where has_stitched_crc32() says so.
#define RSG_STITCHED \
  __attribute__((target("avx512f,avx512bw,avx512dq,avx512vl,avx512vbmi,vpclmulqdq,pclmul,bmi,bmi2,popcnt")))
// The per-chunk helpers must inline into the loop: as calls they cost more than the copy saves.
#define RSG_STITCHED_INLINE RSG_STITCHED __attribute__((always_inline)) inline

namespace rsg::wire::internal {
using detail::ByteMove;
using detail::ChunkedCopyPlan;
using detail::ChunkPiece;
using detail::CopyPlan;
using detail::kChunkBytes;
namespace {

// Folding moves the running remainder of the CRC (sixteen bytes per 128-bit lane) D bits further
// along the message: lane * x^D mod P, computed as the lane's low qword times x^(D+32) mod P plus
// its high qword times x^(D-32) mod P, both bit-reflected like the CRC and shifted left by one for
// the carry-less product of reflected operands (Gopal et al., "Fast CRC Computation for Generic
// Polynomials Using PCLMULQDQ", Intel, 2009).

constexpr std::uint64_t kPolynomial = 0x1'04C1'1DB7;  // CRC-32/ISO-HDLC, x^32 term included

constexpr std::uint32_t x_pow_mod_p(unsigned exponent) {
  std::uint64_t remainder = 1;
  for (unsigned i = 0; i < exponent; ++i) {
    remainder <<= 1;
    if (remainder >> 32) remainder ^= kPolynomial;
  }
  return static_cast<std::uint32_t>(remainder);
}

constexpr std::uint64_t reflected(std::uint32_t value) {
  std::uint64_t result = 0;
  for (unsigned bit = 0; bit < 32; ++bit)
    if (value >> bit & 1U) result |= std::uint64_t{1} << (31 - bit);
  return result;
}

struct FoldConstants {
  std::uint64_t low;   // multiplies a lane's low qword
  std::uint64_t high;  // multiplies its high qword
};

constexpr FoldConstants fold_by(unsigned bits) {
  return {reflected(x_pow_mod_p(bits + 32)) << 1, reflected(x_pow_mod_p(bits - 32)) << 1};
}

// The published constants for folding by 512 and 128 bits (Linux's crc32-pclmul) check the derivation.
static_assert(fold_by(512).low == 0x1'5444'2BD4 && fold_by(512).high == 0x1'C6E4'1596);
static_assert(fold_by(128).low == 0x1'7519'97D0 && fold_by(128).high == 0xCCAA'009E);

// Independent remainders, to cover the multiply latency. Four already keep an Intel Xeon's
// multiplier busy (a fold's latency is a few times VPCLMULQDQ's issue interval); eight were no
// faster there (docs/benchmarks/wire.md).
constexpr std::size_t kChunksPerRound = 4;
constexpr std::size_t kRoundBytes = kChunksPerRound * kChunkBytes;
constexpr std::size_t kMinStitchedBytes = kRoundBytes;
constexpr __mmask64 kWholeChunk = ~__mmask64{0};

RSG_STITCHED_INLINE __m512i fold_vector(FoldConstants k) {
  return _mm512_set4_epi64(static_cast<long long>(k.high), static_cast<long long>(k.low),
                           static_cast<long long>(k.high), static_cast<long long>(k.low));
}

/// remainder * x^D + data, where `k` folds by D bits.
RSG_STITCHED_INLINE __m512i fold_in(__m512i remainder, __m512i k, __m512i data) {
  constexpr int kXor3 = 0x96;
  return _mm512_ternarylogic_epi64(_mm512_clmulepi64_epi128(remainder, k, 0x00),
                                   _mm512_clmulepi64_epi128(remainder, k, 0x11), data, kXor3);
}

/// Bytes [first, end) of a chunk, as a mask.
RSG_STITCHED_INLINE __mmask64 range_mask(unsigned first, unsigned end) {
  return _bzhi_u64(kWholeChunk, end) & ~_bzhi_u64(kWholeChunk, first);
}

// Masked accesses that straddle a page boundary, with masked-off bytes on the far side, are slow:
// far slower than a plain one on AMD Zen 4 (docs/benchmarks/wire.md). A masked load did the
// same in one placement, reaching masked-off into the page before a static array (not with both
// pages in use). A frame or struct placed at such an offset would pay that on every
// frame. So a partial chunk whose 64 bytes would straddle a page goes through 64-byte-aligned
// windows, which never do, with the bytes rotated into place.

constexpr std::uintptr_t kPageBytes = 4096;

RSG_STITCHED_INLINE bool straddles_page(const void* chunk) {
  return reinterpret_cast<std::uintptr_t>(chunk) % kPageBytes > kPageBytes - kChunkBytes;
}

/// Rotates `bytes` so that byte `from` moves to position `to` (mod 64), keeping only `keep`.
RSG_STITCHED_INLINE __m512i rotate(__m512i bytes, unsigned from, unsigned to, __mmask64 keep) {
  // vpermb reads only the low 6 bits of each index: result[j] = bytes[(j + from - to) mod 64].
  const __m512i indices = _mm512_add_epi8(
      _mm512_set_epi8(63, 62, 61, 60, 59, 58, 57, 56, 55, 54, 53, 52, 51, 50, 49, 48, 47, 46, 45, 44, 43, 42,
                      41, 40, 39, 38, 37, 36, 35, 34, 33, 32, 31, 30, 29, 28, 27, 26, 25, 24, 23, 22, 21, 20,
                      19, 18, 17, 16, 15, 14, 13, 12, 11, 10, 9, 8, 7, 6, 5, 4, 3, 2, 1, 0),
      _mm512_set1_epi8(static_cast<char>(from - to)));
  return _mm512_maskz_permutexvar_epi8(keep, indices, bytes);
}

/// Stores bytes [first, first + count) of `bytes` at `to + first`, touching no other byte.
RSG_STITCHED_INLINE void store_range(std::byte* to, __m512i bytes, unsigned first, unsigned count) {
  if (!straddles_page(to)) {
    _mm512_mask_storeu_epi8(to, range_mask(first, first + count), bytes);
    return;
  }
  const std::uintptr_t begin = reinterpret_cast<std::uintptr_t>(to) + first;
  auto* window = reinterpret_cast<std::byte*>(begin & ~std::uintptr_t{kChunkBytes - 1});
  const auto shift = static_cast<unsigned>(begin % kChunkBytes);  // where byte `first` lands in the window
  const __m512i rotated = rotate(bytes, first, shift, kWholeChunk);
  const unsigned end = shift + count;
  _mm512_mask_storeu_epi8(window, range_mask(shift, std::min(end, 64U)), rotated);
  if (end > kChunkBytes) _mm512_mask_storeu_epi8(window + kChunkBytes, range_mask(0, end - 64), rotated);
}

/// Bytes [first, first + count) from `from + first` at positions [first, first + count), the others
/// zero, reading no other byte.
template <class Byte>
RSG_STITCHED_INLINE __m512i load_range(const Byte* from, unsigned first, unsigned count) {
  if (!straddles_page(from)) return _mm512_maskz_loadu_epi8(range_mask(first, first + count), from);
  const std::uintptr_t begin = reinterpret_cast<std::uintptr_t>(from) + first;
  const auto* window = reinterpret_cast<const Byte*>(begin & ~std::uintptr_t{kChunkBytes - 1});
  const auto shift = static_cast<unsigned>(begin % kChunkBytes);
  const unsigned end = shift + count;
  __m512i loaded = _mm512_maskz_loadu_epi8(range_mask(shift, std::min(end, 64U)), window);
  if (end > kChunkBytes)
    loaded = _mm512_mask_loadu_epi8(loaded, range_mask(0, end - 64), window + kChunkBytes);
  return rotate(loaded, shift, first, range_mask(first, first + count));
}

/// A range mask's first byte and length.
RSG_STITCHED_INLINE unsigned first_byte(__mmask64 range) { return static_cast<unsigned>(_tzcnt_u64(range)); }
RSG_STITCHED_INLINE unsigned byte_count(__mmask64 range) {
  return static_cast<unsigned>(_mm_popcnt_u64(range));
}

/// Where the struct byte matching frame offset `at` would be. Only the bytes a mask selects are
/// touched, so the address may lie outside the struct; integer arithmetic keeps that defined.
template <class Byte>
Byte* struct_address(Byte* base, std::size_t at, std::ptrdiff_t delta) {
  return reinterpret_cast<Byte*>(reinterpret_cast<std::uintptr_t>(base) + at +
                                 static_cast<std::uintptr_t>(delta));
}

/// The frame's bytes seen from the padded frame's start, `padding` bytes before the first byte.
/// The kernel reaches the padding only through masked accesses with those bytes masked off.
template <class Byte>
Byte* padded_origin(Byte* frame, std::size_t padding) {
  return reinterpret_cast<Byte*>(reinterpret_cast<std::uintptr_t>(frame) - padding);
}

/// Follows the plan's runs of whole chunks along the frame, keeping the current run in registers:
/// the per-chunk path then reads nothing from the plan, which it would have to reload after every
/// store into the struct. The plan is read where a run ends, a few times per frame.
class WholeRuns {
 public:
  explicit WholeRuns(const ChunkedCopyPlan& plan) : plan_(&plan) {}

  /// Whether frame bytes [at, at + bytes) lie in one run; delta() is then its struct delta.
  /// Calls come in increasing `at`.
  RSG_STITCHED_INLINE bool cover(std::size_t at, std::size_t bytes) {
    if (at >= end_) {
      const std::size_t chunk = at / kChunkBytes;
      if (!plan_->is_whole_chunk(chunk)) return false;
      delta_ = plan_->whole_chunk_delta(chunk);
      end_ = plan_->whole_run_end(chunk);
    }
    return at + bytes <= end_;
  }
  std::ptrdiff_t delta() const { return delta_; }
  /// Where the run that the last successful cover() found ends.
  std::size_t end() const { return end_; }
  const ChunkedCopyPlan& plan() const { return *plan_; }

 private:
  const ChunkedCopyPlan* plan_;
  std::size_t end_ = 0;
  std::ptrdiff_t delta_ = 0;
};

/// What decoding and encoding share: rounds inside one run of whole chunks are one block copy,
/// `Direction::block` says from where to where.
template <class Direction>
class ChunkCopy {
 public:
  explicit ChunkCopy(const ChunkedCopyPlan& plan) : runs_(plan) {}

  /// Folds the rounds from `at` on that lie inside one run of whole chunks and end by `limit`,
  /// copying them as they go; returns where it stopped (`at` if the round at `at` is not inside a
  /// run). The loop carries two pointers and nothing else: with the run's bookkeeping inside it,
  /// the compiler spilled counters to the stack and the round was slower than its multiplies
  /// (on an Intel Xeon, docs/benchmarks/wire.md).
  RSG_STITCHED_INLINE std::size_t fold_run(std::size_t at, std::size_t limit, __m512i k, __m512i& r0,
                                           __m512i& r1, __m512i& r2, __m512i& r3) {
    if (!runs_.cover(at, kRoundBytes)) return at;
    const std::size_t end = std::min(runs_.end(), limit);
    auto [from, to] = static_cast<Direction&>(*this).block(at, runs_.delta());
    for (; at + kRoundBytes <= end; at += kRoundBytes, from += kRoundBytes, to += kRoundBytes) {
      const __m512i c0 = _mm512_loadu_si512(from);
      const __m512i c1 = _mm512_loadu_si512(from + kChunkBytes);
      const __m512i c2 = _mm512_loadu_si512(from + 2 * kChunkBytes);
      const __m512i c3 = _mm512_loadu_si512(from + 3 * kChunkBytes);
      _mm512_storeu_si512(to, c0);
      _mm512_storeu_si512(to + kChunkBytes, c1);
      _mm512_storeu_si512(to + 2 * kChunkBytes, c2);
      _mm512_storeu_si512(to + 3 * kChunkBytes, c3);
      r0 = fold_in(r0, k, c0);
      r1 = fold_in(r1, k, c1);
      r2 = fold_in(r2, k, c2);
      r3 = fold_in(r3, k, c3);
    }
    return at;
  }

 protected:
  WholeRuns runs_;
};

struct Block {
  const std::byte* from;
  std::byte* to;
};

/// Decoding: each chunk is read from the frame and written to the struct where the plan says.
class ScatterChunks : public ChunkCopy<ScatterChunks> {
 public:
  ScatterChunks(const std::uint8_t* frame, const ChunkedCopyPlan& plan, std::byte* base)
      : ChunkCopy(plan),
        frame_(padded_origin(reinterpret_cast<const std::byte*>(frame), plan.head_padding())),
        base_(base) {}

  /// The padded frame's bytes [at, at + 64) that `valid` selects, the others zero.
  RSG_STITCHED_INLINE __m512i operator()(std::size_t at, __mmask64 valid) {
    const __m512i bytes = valid == kWholeChunk
                              ? _mm512_loadu_si512(frame_ + at)
                              : load_range(frame_ + at, first_byte(valid), byte_count(valid));
    if (runs_.cover(at, kChunkBytes)) {
      _mm512_storeu_si512(struct_address(base_, at, runs_.delta()), bytes);
      return bytes;
    }
    for (const ChunkPiece& piece : runs_.plan().chunk_pieces(at / kChunkBytes))
      store_range(struct_address(base_, at, piece.struct_delta), bytes, first_byte(piece.bytes),
                  byte_count(piece.bytes));
    return bytes;
  }

  RSG_STITCHED_INLINE Block block(std::size_t at, std::ptrdiff_t delta) const {
    return {frame_ + at, struct_address(base_, at, delta)};
  }

 private:
  const std::byte* frame_;
  std::byte* base_;
};

/// Encoding: each chunk is assembled from the struct where the plan says, the rest (the header)
/// kept from the frame.
class GatherChunks : public ChunkCopy<GatherChunks> {
 public:
  GatherChunks(std::uint8_t* frame, const ChunkedCopyPlan& plan, const std::byte* base)
      : ChunkCopy(plan),
        frame_(padded_origin(reinterpret_cast<std::byte*>(frame), plan.head_padding())),
        base_(base) {}

  RSG_STITCHED_INLINE __m512i operator()(std::size_t at, __mmask64 valid) {
    if (runs_.cover(at, kChunkBytes)) {
      const __m512i bytes = _mm512_loadu_si512(struct_address(base_, at, runs_.delta()));
      _mm512_storeu_si512(frame_ + at, bytes);
      return bytes;
    }
    __m512i bytes = _mm512_setzero_si512();
    __mmask64 moved = 0;
    for (const ChunkPiece& piece : runs_.plan().chunk_pieces(at / kChunkBytes)) {
      bytes = _mm512_or_si512(bytes, load_range(struct_address(base_, at, piece.struct_delta),
                                                first_byte(piece.bytes), byte_count(piece.bytes)));
      moved |= piece.bytes;
    }
    // What no move covers is the header, one contiguous range at the frame's start.
    if (const __mmask64 kept = valid & ~moved)
      bytes = _mm512_or_si512(bytes, load_range(frame_ + at, first_byte(kept), byte_count(kept)));
    if (valid == kWholeChunk)
      _mm512_storeu_si512(frame_ + at, bytes);
    else  // the first chunk, which starts with padding
      store_range(frame_ + at, bytes, first_byte(valid), byte_count(valid));
    return bytes;
  }

  RSG_STITCHED_INLINE Block block(std::size_t at, std::ptrdiff_t delta) const {
    return {struct_address(base_, at, delta), frame_ + at};
  }

 private:
  std::byte* frame_;
  const std::byte* base_;
};

/// The CRC of the message whose remainder, folded down to 128 bits, is `remainder`: ISA-L's closing
/// sequence (crc32_gzip_refl_by16_10.asm, ".128_done"), folding to 64 bits, then to 32, then a
/// Barrett reduction, with ISA-L's constants for the last step.
RSG_STITCHED_INLINE std::uint32_t finish(__m128i remainder) {
  constexpr std::uint64_t kBarrettQuotient = 0x1'F701'1640;    // ISA-L's rk7
  constexpr std::uint64_t kBarrettPolynomial = 0x1'DB71'0640;  // ISA-L's rk8
  const __m128i fold = _mm_set_epi64x(static_cast<long long>(reflected(x_pow_mod_p(64)) << 1),
                                      static_cast<long long>(fold_by(128).high));
  __m128i x = _mm_xor_si128(_mm_clmulepi64_si128(remainder, fold, 0x00), _mm_srli_si128(remainder, 8));
  x = _mm_xor_si128(_mm_clmulepi64_si128(_mm_slli_si128(x, 4), fold, 0x10), x);
  x = _mm_and_si128(x, _mm_set_epi64x(-1, static_cast<long long>(0xFFFF'FFFF'0000'0000)));
  const __m128i barrett =
      _mm_set_epi64x(static_cast<long long>(kBarrettPolynomial), static_cast<long long>(kBarrettQuotient));
  __m128i t = _mm_xor_si128(_mm_clmulepi64_si128(x, barrett, 0x00), x);
  t = _mm_and_si128(t, _mm_set_epi64x(0, -1));
  t = _mm_ternarylogic_epi64(_mm_clmulepi64_si128(t, barrett, 0x10), t, x, 0x96);
  return ~static_cast<std::uint32_t>(_mm_extract_epi32(t, 2));
}

/// CRC-32 of the frame that `chunks(at, valid)` yields 64 bytes at a time, as a padded frame of
/// `padded_size` (a multiple of 64, at least 256) bytes whose first `padding` bytes are not the
/// frame's. Leading zeros do not change a CRC computed from a zero start, so the padding reads as
/// zeros and the frame's end falls on a chunk boundary: no partial chunk at the end.
template <class Chunks>
RSG_STITCHED std::uint32_t stitched_crc32(std::size_t padded_size, std::size_t padding,
                                          const Chunks& source) {
  // A local copy the compiler can keep in registers: the caller's object lives in memory, and every
  // store into the struct would make the compiler reload its members.
  Chunks chunks = source;
  const __m512i by_round = fold_vector(fold_by(8 * kRoundBytes));
  const __m512i by_chunk = fold_vector(fold_by(8 * kChunkBytes));

  // The CRC starts from all ones: the same as a zero start with the frame's first 32 bits
  // inverted, which may reach into the second chunk.
  const auto first = static_cast<unsigned>(padding);
  const __m512i invert0 = _mm512_maskz_set1_epi8(range_mask(first, std::min(first + 4, 64U)), -1);
  const __m512i invert1 = _mm512_maskz_set1_epi8(first + 4 > 64 ? range_mask(0, first + 4 - 64) : 0, -1);
  __m512i r0 = _mm512_xor_si512(chunks(0, range_mask(first, 64)), invert0);
  __m512i r1 = _mm512_xor_si512(chunks(kChunkBytes, kWholeChunk), invert1);
  __m512i r2 = chunks(2 * kChunkBytes, kWholeChunk);
  __m512i r3 = chunks(3 * kChunkBytes, kWholeChunk);
  std::size_t at = kRoundBytes;
  while (at + kRoundBytes <= padded_size) {
    if (const std::size_t next = chunks.fold_run(at, padded_size, by_round, r0, r1, r2, r3); next != at) {
      at = next;
      continue;
    }
    // A round with a chunk outside the runs: chunk by chunk, each by its pieces.
    r0 = fold_in(r0, by_round, chunks(at, kWholeChunk));
    r1 = fold_in(r1, by_round, chunks(at + kChunkBytes, kWholeChunk));
    r2 = fold_in(r2, by_round, chunks(at + 2 * kChunkBytes, kWholeChunk));
    r3 = fold_in(r3, by_round, chunks(at + 3 * kChunkBytes, kWholeChunk));
    at += kRoundBytes;
  }
  __m512i remainder = fold_in(fold_in(fold_in(r0, by_chunk, r1), by_chunk, r2), by_chunk, r3);
  for (; at < padded_size; at += kChunkBytes)
    remainder = fold_in(remainder, by_chunk, chunks(at, kWholeChunk));

  // Four lanes into one: lane i lies (3 - i) * 128 bits before the last lane.
  const __m512i by_lane = _mm512_set_epi64(
      0, 0, static_cast<long long>(fold_by(128).high), static_cast<long long>(fold_by(128).low),
      static_cast<long long>(fold_by(256).high), static_cast<long long>(fold_by(256).low),
      static_cast<long long>(fold_by(384).high), static_cast<long long>(fold_by(384).low));
  const __m512i folded = _mm512_xor_si512(_mm512_clmulepi64_epi128(remainder, by_lane, 0x00),
                                          _mm512_clmulepi64_epi128(remainder, by_lane, 0x11));
  __m128i lane = _mm512_extracti64x2_epi64(remainder, 3);
  lane = _mm_ternarylogic_epi64(lane, _mm512_extracti64x2_epi64(folded, 0),
                                _mm512_extracti64x2_epi64(folded, 1), 0x96);
  lane = _mm_xor_si128(lane, _mm512_extracti64x2_epi64(folded, 2));
  return finish(lane);
}

bool detect_stitched_crc32() {
  __builtin_cpu_init();
  return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512bw") &&
         __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512vl") &&
         __builtin_cpu_supports("avx512vbmi") && __builtin_cpu_supports("vpclmulqdq") &&
         __builtin_cpu_supports("bmi") && __builtin_cpu_supports("bmi2") && __builtin_cpu_supports("popcnt");
}

/// Long enough for four chunks, and the frame the plan was made for (its selection's length).
bool fits_stitched(std::size_t size, const ChunkedCopyPlan& plan) {
  return size >= kMinStitchedBytes && (size + plan.head_padding()) % kChunkBytes == 0;
}

}  // namespace

bool has_stitched_crc32() noexcept {
  static const bool supported = detect_stitched_crc32();
  return supported;
}

void copy_to_struct(std::span<const std::uint8_t> frame, const CopyPlan& plan, std::byte* base) noexcept {
  for (const ByteMove& move : plan.moves())
    std::memcpy(base + (move.frame_begin + move.struct_delta), frame.data() + move.frame_begin,
                move.frame_end - move.frame_begin);
}

std::uint32_t crc32_scatter_portable(std::span<const std::uint8_t> frame, const ChunkedCopyPlan& plan,
                                     std::byte* base) noexcept {
  copy_to_struct(frame, plan.plan(), base);
  return crc32(frame);
}

void copy_to_frame(std::span<std::uint8_t> frame, const CopyPlan& plan, const std::byte* base) noexcept {
  for (const ByteMove& move : plan.moves())
    std::memcpy(frame.data() + move.frame_begin, base + (move.frame_begin + move.struct_delta),
                move.frame_end - move.frame_begin);
}

std::uint32_t gather_crc32_portable(std::span<std::uint8_t> frame, const ChunkedCopyPlan& plan,
                                    const std::byte* base) noexcept {
  copy_to_frame(frame, plan.plan(), base);
  return crc32(frame);
}

std::uint32_t crc32_scatter_stitched(std::span<const std::uint8_t> frame, const ChunkedCopyPlan& plan,
                                     std::byte* base) noexcept {
  if (!fits_stitched(frame.size(), plan)) return crc32_scatter_portable(frame, plan, base);
  return stitched_crc32(frame.size() + plan.head_padding(), plan.head_padding(),
                        ScatterChunks(frame.data(), plan, base));
}

std::uint32_t gather_crc32_stitched(std::span<std::uint8_t> frame, const ChunkedCopyPlan& plan,
                                    const std::byte* base) noexcept {
  if (!fits_stitched(frame.size(), plan)) return gather_crc32_portable(frame, plan, base);
  return stitched_crc32(frame.size() + plan.head_padding(), plan.head_padding(),
                        GatherChunks(frame.data(), plan, base));
}

std::uint32_t crc32_scatter(std::span<const std::uint8_t> frame, const ChunkedCopyPlan& plan,
                            std::byte* base) noexcept {
  return has_stitched_crc32() ? crc32_scatter_stitched(frame, plan, base)
                              : crc32_scatter_portable(frame, plan, base);
}

std::uint32_t gather_crc32(std::span<std::uint8_t> frame, const ChunkedCopyPlan& plan,
                           const std::byte* base) noexcept {
  return has_stitched_crc32() ? gather_crc32_stitched(frame, plan, base)
                              : gather_crc32_portable(frame, plan, base);
}

}  // namespace rsg::wire::internal
