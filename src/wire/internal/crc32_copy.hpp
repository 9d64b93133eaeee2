// The frame's CRC-32 computed in the same pass that moves its field bytes to or from a struct.
//
// Checking the CRC and then copying costs the CRC plus a memcpy of the frame. Stitched together, the
// copy rides in the load and store slots that the CRC's carry-less multiplies leave idle, and
// decoding or encoding a full frame costs little more than the CRC alone. ISA-L stitches a copy
// only into its CRC16-T10DIF, hence this kernel. Its final reduction is ISA-L's crc32_gzip_refl,
// and the unit tests hold both implementations to ISA-L bit for bit.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

#include "rsg/wire/detail/copy_plan.hpp"

namespace rsg::wire::internal {

/// Decoding: returns the CRC-32 of `frame` and copies the bytes of each of the plan's moves to `base`.
std::uint32_t crc32_scatter(std::span<const std::uint8_t> frame, const detail::ChunkedCopyPlan& plan,
                            std::byte* base) noexcept;

/// Encoding: fills the bytes of each move from `base`, keeps the other bytes of `frame` (the
/// header) and returns the CRC-32 of the result.
std::uint32_t gather_crc32(std::span<std::uint8_t> frame, const detail::ChunkedCopyPlan& plan,
                           const std::byte* base) noexcept;

/// The moves alone, without a CRC: frame to struct, and struct to frame.
void copy_to_struct(std::span<const std::uint8_t> frame, const detail::CopyPlan& plan,
                    std::byte* base) noexcept;
void copy_to_frame(std::span<std::uint8_t> frame, const detail::CopyPlan& plan,
                   const std::byte* base) noexcept;

// The implementations behind the two, picked once by CPU; exposed for the tests.

/// True where the stitched kernel runs: AVX-512 (F, BW, DQ, VL), VPCLMULQDQ and BMI2.
bool has_stitched_crc32() noexcept;
/// Any x86-64: ISA-L's CRC, then one memcpy per move.
std::uint32_t crc32_scatter_portable(std::span<const std::uint8_t> frame, const detail::ChunkedCopyPlan& plan,
                                     std::byte* base) noexcept;
std::uint32_t gather_crc32_portable(std::span<std::uint8_t> frame, const detail::ChunkedCopyPlan& plan,
                                    const std::byte* base) noexcept;
/// Only where has_stitched_crc32().
std::uint32_t crc32_scatter_stitched(std::span<const std::uint8_t> frame, const detail::ChunkedCopyPlan& plan,
                                     std::byte* base) noexcept;
std::uint32_t gather_crc32_stitched(std::span<std::uint8_t> frame, const detail::ChunkedCopyPlan& plan,
                                    const std::byte* base) noexcept;

}  // namespace rsg::wire::internal
