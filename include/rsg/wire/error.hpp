// Why a frame was rejected: the spec's validation categories.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string_view>

namespace rsg::wire {

/// The spec's error categories, in the order its validation checks them.
enum class ErrorCategory : std::uint8_t {
  kNone = 0,
  kTruncated,
  kLengthMismatch,
  kBadCrc,
  kBadRequest,
  kReservedBits,
  kSelectionMismatch,
  kBadValue,
};

inline constexpr std::size_t kErrorCategoryCount = 7;  // excluding kNone

inline constexpr std::array<std::string_view, kErrorCategoryCount + 1> kErrorCategoryNames = {
    "none",        "truncated",     "length_mismatch",    "bad_crc",
    "bad_request", "reserved_bits", "selection_mismatch", "bad_value"};

constexpr std::string_view to_string(ErrorCategory category) {
  return kErrorCategoryNames[static_cast<std::size_t>(category)];
}

constexpr std::optional<ErrorCategory> parse_error_category(std::string_view name) {
  for (std::size_t i = 0; i < kErrorCategoryNames.size(); ++i)
    if (kErrorCategoryNames[i] == name) return static_cast<ErrorCategory>(i);
  return std::nullopt;
}

/// A rejection: its category plus a human-readable detail. Fixed-size so that rejecting a frame
/// never allocates.
class FrameError {
 public:
  // Only the terminator: every decode builds a FrameError, and clearing 112 bytes each time shows
  // up in the codec's benchmark.
  FrameError() { message_[0] = '\0'; }
  FrameError(ErrorCategory category, const char* format, ...) __attribute__((format(printf, 3, 4)));

  ErrorCategory category() const { return category_; }
  std::string_view message() const { return {message_.data()}; }
  explicit operator bool() const { return category_ != ErrorCategory::kNone; }

 private:
  ErrorCategory category_ = ErrorCategory::kNone;
  std::array<char, 112> message_;  // NUL-terminated
};

}  // namespace rsg::wire
