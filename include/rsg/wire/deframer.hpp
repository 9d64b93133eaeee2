// Finds frames in a byte stream (TCP, serial line, capture file) however it is chunked.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "rsg/wire/frame.hpp"

namespace rsg::wire {

/// Accumulates bytes and hands out every span that is a CRC-correct frame. Bytes that cannot start
/// one are skipped one at a time and counted, so the stream resynchronises after garbage. A frame
/// handed out may still fail `decode` (e.g. bad_value); the deframer only establishes framing.
class Deframer {
 public:
  /// Calls `on_frame(std::span<const std::uint8_t>)` for each frame completed by `chunk`.
  /// The span is valid only during the call.
  template <class OnFrame>
  void feed(std::span<const std::uint8_t> chunk, OnFrame&& on_frame) {
    while (!chunk.empty()) {
      const std::size_t room = buffer_.size() - size_;
      const std::size_t take = chunk.size() < room ? chunk.size() : room;
      std::copy_n(chunk.data(), take, buffer_.data() + size_);
      size_ += take;
      chunk = chunk.subspan(take);
      std::size_t start = 0;
      while (true) {
        const Scan scan = scan_at(start);
        if (scan.kind == Scan::kNeedMore) break;
        if (scan.kind == Scan::kFrame) {
          on_frame(std::span<const std::uint8_t>(buffer_.data() + start, scan.size));
          ++frames_;
          start += scan.size;
        } else {
          ++skipped_bytes_;
          ++start;
        }
      }
      std::copy(buffer_.begin() + static_cast<std::ptrdiff_t>(start),
                buffer_.begin() + static_cast<std::ptrdiff_t>(size_), buffer_.begin());
      size_ -= start;
    }
  }

  std::uint64_t frames() const { return frames_; }
  std::uint64_t skipped_bytes() const { return skipped_bytes_; }
  /// Bytes held back waiting for the rest of a possible frame.
  std::size_t pending_bytes() const { return size_; }

 private:
  struct Scan {
    enum Kind { kNeedMore, kFrame, kSkip } kind;
    std::size_t size;
  };
  Scan scan_at(std::size_t start) const noexcept;

  // Twice the largest frame: a full frame always fits behind a partial one.
  std::array<std::uint8_t, 2 * kMaxFrameBytes> buffer_{};
  std::size_t size_ = 0;
  std::uint64_t frames_ = 0;
  std::uint64_t skipped_bytes_ = 0;
};

}  // namespace rsg::wire
