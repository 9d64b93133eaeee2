// What every parser of user text returns (CONTRIBUTING.md, "Errors"): the value, or what is wrong
// with the text, in words for the user who typed it. Never both, never neither.
#pragma once

#include <optional>
#include <string>
#include <utility>

namespace rsg::wire {

/// Why a text was refused; converts to any Parsed<T>: `return ParseFailure{"'x' is not a field"};`
struct ParseFailure {
  std::string why;
};

template <class T>
class [[nodiscard]] Parsed {
 public:
  Parsed(T value) : value_(std::move(value)) {}  // NOLINT: implicit, `return value;`
  Parsed(ParseFailure failure)
      : error_(std::move(failure.why)) {}  // NOLINT: implicit, `return ParseFailure{...};`

  explicit operator bool() const noexcept { return value_.has_value(); }
  /// The value; only when the parse succeeded.
  const T& value() const& { return *value_; }
  T&& value() && { return std::move(*value_); }
  const T& operator*() const& { return *value_; }
  const T* operator->() const { return &*value_; }
  /// What is wrong with the text; "" when the parse succeeded.
  const std::string& error() const noexcept { return error_; }

 private:
  std::optional<T> value_;
  std::string error_;
};

}  // namespace rsg::wire
