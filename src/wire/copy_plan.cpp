#include "rsg/wire/detail/copy_plan.hpp"

#include <algorithm>

namespace rsg::wire::detail {

CopyPlan::CopyPlan(const Selection& selection, const FieldLayout& layout) noexcept : selection_(selection) {
  std::uint32_t frame_offset = kHeaderBytes;
  for (const FieldInfo& field : kFields) {
    const std::uint32_t struct_offset = layout.offsets[field.index];
    if (!selection.contains(field.id())) {
      add_fill(struct_offset, field.value_bytes());
      continue;
    }
    // Wire and memory bytes agree for every type (little-endian host); an error set's memory form
    // is a uint64 whose low 5 bytes are its wire form.
    add_move(frame_offset, field.wire_bytes, struct_offset);
    if (field.value_bytes() > field.wire_bytes)
      add_fill(struct_offset + field.wire_bytes, field.value_bytes() - field.wire_bytes);
    frame_offset += field.wire_bytes;
  }
  covered_bytes_ = frame_offset;
}

void CopyPlan::add_move(std::uint32_t frame_offset, std::uint32_t size, std::uint32_t struct_offset) {
  const std::ptrdiff_t delta = std::ptrdiff_t{struct_offset} - std::ptrdiff_t{frame_offset};
  if (move_count_ != 0) {
    ByteMove& last = moves_[move_count_ - 1];
    if (last.frame_end == frame_offset && last.struct_delta == delta) {
      last.frame_end += size;
      return;
    }
  }
  moves_[move_count_++] = {frame_offset, frame_offset + size, delta};
}

void CopyPlan::add_fill(std::uint32_t struct_offset, std::uint32_t size) {
  if (fill_count_ != 0) {
    ByteFill& last = fills_[fill_count_ - 1];
    if (last.begin + last.size == struct_offset) {
      last.size += size;
      return;
    }
  }
  fills_[fill_count_++] = {struct_offset, size};
}

ChunkedCopyPlan::ChunkedCopyPlan(const Selection& selection, const FieldLayout& layout) noexcept
    : plan_(selection, layout),
      head_padding_((kChunkBytes - plan_.covered_bytes() % kChunkBytes) % kChunkBytes) {
  std::size_t piece_count = 0;
  std::size_t chunk = 0;
  for (const ByteMove& move : plan_.moves()) {
    const std::size_t begin = move.frame_begin + head_padding_;  // positions in the padded frame
    const std::size_t end = move.frame_end + head_padding_;
    const std::ptrdiff_t delta = move.struct_delta - static_cast<std::ptrdiff_t>(head_padding_);
    for (std::size_t at = begin / kChunkBytes * kChunkBytes; at < end; at += kChunkBytes) {
      while (chunk < at / kChunkBytes) chunk_starts_[++chunk] = static_cast<std::uint8_t>(piece_count);
      const std::size_t first = std::max(begin, at) - at;
      const std::size_t last = std::min(end, at + kChunkBytes) - at;
      const std::uint64_t below_last =
          last == kChunkBytes ? ~std::uint64_t{0} : (std::uint64_t{1} << last) - 1;
      pieces_[piece_count++] = {delta, below_last & ~((std::uint64_t{1} << first) - 1)};
      if (first == 0 && last == kChunkBytes) {
        whole_chunks_ |= std::uint64_t{1} << chunk;
        whole_chunk_deltas_[chunk] = delta;
      }
    }
  }
  while (chunk < kMaxChunks) chunk_starts_[++chunk] = static_cast<std::uint8_t>(piece_count);

  // Adjacent whole chunks with the same delta belong to one move: moves that meet with the same
  // delta were merged above.
  for (std::size_t c = kMaxChunks; c-- > 0;) {
    if (!is_whole_chunk(c)) continue;
    const bool run_goes_on =
        c + 1 < kMaxChunks && is_whole_chunk(c + 1) && whole_chunk_deltas_[c + 1] == whole_chunk_deltas_[c];
    whole_run_ends_[c] =
        run_goes_on ? whole_run_ends_[c + 1] : static_cast<std::uint32_t>((c + 1) * kChunkBytes);
  }
}

}  // namespace rsg::wire::detail
