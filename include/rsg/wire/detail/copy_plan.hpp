// Internal, not rsg's API (FrameCodec holds one by value, so its header must see it): namespace
// rsg::wire::detail, installed, free to change in any release (CONTRIBUTING.md, "Layers").
// Which bytes go where when one selection's fields move between a frame and a struct.
//
// The field walk (44 rows: present? where on the wire? where in the struct?) is done once per
// selection and condensed into a few long byte moves, so that copying a full frame is a handful of
// block copies instead of 44 small ones. A robot sends the same selection frame after frame, so
// `FrameCodec` keeps the plan of the last selection it saw.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "rsg/wire/field_layout.hpp"
#include "rsg/wire/field_table.hpp"
#include "rsg/wire/frame.hpp"
#include "rsg/wire/selection.hpp"

namespace rsg::wire::detail {

/// Frame bytes [frame_begin, frame_end) correspond to the struct bytes at the same offsets plus
/// `struct_delta`. Offsets count from the start of the frame, header included.
struct ByteMove {
  std::uint32_t frame_begin;
  std::uint32_t frame_end;
  std::ptrdiff_t struct_delta;
};

/// Struct bytes [begin, begin + size) that a decoded frame leaves zero: fields it does not carry and
/// the high bytes of the 5-byte error sets, which are 8 bytes in memory.
struct ByteFill {
  std::uint32_t begin;
  std::uint32_t size;
};

/// The part of one move that falls into one 64-byte chunk of the (padded) frame.
struct ChunkPiece {
  std::ptrdiff_t struct_delta;  ///< struct offset minus padded position
  std::uint64_t bytes;          ///< bit i: byte i of the chunk
};

inline constexpr std::size_t kChunkBytes = 64;
inline constexpr std::size_t kMaxChunks = (kMaxFrameBytes + kChunkBytes - 1) / kChunkBytes;

class CopyPlan {
 public:
  CopyPlan(const Selection& selection, const FieldLayout& layout) noexcept;

  const Selection& selection() const { return selection_; }
  /// Bytes the frame's CRC covers: header and the selection's data.
  std::size_t covered_bytes() const { return covered_bytes_; }
  /// Sorted by frame offset; adjacent fields contiguous on both sides are merged into one move.
  std::span<const ByteMove> moves() const { return std::span(moves_).first(move_count_); }
  std::span<const ByteFill> fills() const { return std::span(fills_).first(fill_count_); }

 private:
  void add_move(std::uint32_t frame_offset, std::uint32_t size, std::uint32_t struct_offset);
  void add_fill(std::uint32_t struct_offset, std::uint32_t size);

  // Filled only as far as the counts say: clearing them would cost more than building the plan.
  Selection selection_;
  std::size_t covered_bytes_ = 0;
  std::array<ByteMove, kFieldCount> moves_;
  std::size_t move_count_ = 0;
  std::array<ByteFill, kFieldCount> fills_;  // at most one per field: absent, or widened
  std::size_t fill_count_ = 0;
};

/// A copy plan's moves cut into 64-byte chunks, for a copy that goes a chunk at a time: the
/// stitched CRC kernel (src/wire/internal/crc32_copy.hpp). The chunks cover the CRC-covered bytes preceded
/// by `head_padding()` zero bytes, so that they end where the frame ends; positions and deltas
/// here count in that padded frame. Built once per selection and kept by `FrameCodec`.
class ChunkedCopyPlan {
 public:
  ChunkedCopyPlan(const Selection& selection, const FieldLayout& layout) noexcept;

  const CopyPlan& plan() const { return plan_; }
  std::size_t head_padding() const { return head_padding_; }
  /// Most chunks of a frame lie inside one move: for those, a whole-chunk copy, no loop, no mask.
  bool is_whole_chunk(std::size_t chunk) const { return whole_chunks_ >> chunk & 1U; }
  std::ptrdiff_t whole_chunk_delta(std::size_t chunk) const { return whole_chunk_deltas_[chunk]; }
  /// Padded position where the run of whole chunks of one move that contains `chunk` ends.
  std::uint32_t whole_run_end(std::size_t chunk) const { return whole_run_ends_[chunk]; }
  /// Every chunk's pieces (a whole chunk has one).
  std::span<const ChunkPiece> chunk_pieces(std::size_t chunk) const {
    return std::span(pieces_).subspan(chunk_starts_[chunk], chunk_starts_[chunk + 1] - chunk_starts_[chunk]);
  }

 private:
  CopyPlan plan_;
  std::size_t head_padding_ = 0;
  std::array<ChunkPiece, kMaxChunks + kFieldCount> pieces_;  // a move spanning k chunks gives k pieces
  std::array<std::uint8_t, kMaxChunks + 1> chunk_starts_{};
  std::uint64_t whole_chunks_ = 0;  // bit c: chunk c lies inside one move
  std::array<std::ptrdiff_t, kMaxChunks> whole_chunk_deltas_;
  std::array<std::uint32_t, kMaxChunks> whole_run_ends_;
  static_assert(kMaxChunks <= 64, "whole_chunks_ has a bit per chunk");
};

}  // namespace rsg::wire::detail
