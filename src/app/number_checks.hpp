// The checks of a number flag, saying what is wrong in words: CLI11's own say "Value fast not in
// range 0.001000 to 1000000.000000" for a word, and print the largest double (309 digits) as the
// bound of a positive number.
//
//   app.add_option("--rate", rate, "Frames per second")->check(rsg::app::number_in(1e-3, 1e6));
//   // --rate fast: "'fast' is not a number"; --rate 0: "0 is not in 0.001..1e+06"
#pragma once

#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <string>

#include "wire/internal/number.hpp"

namespace rsg::app {

/// A number in [low, high].
inline CLI::Validator number_in(double low, double high) {
  return CLI::Validator(
      [low, high](const std::string& text) {
        const auto value = wire::internal::parse_number<double>(text);
        if (!value) return fmt::format("'{}' is not a number", text);
        if (!(*value >= low && *value <= high))
          return fmt::format("{} is not in {:g}..{:g}", text, low, high);
        return std::string();
      },
      fmt::format("NUMBER in {:g}..{:g}", low, high), "");
}

/// A number above 0.
inline CLI::Validator positive_number() {
  return CLI::Validator(
      [](const std::string& text) {
        const auto value = wire::internal::parse_number<double>(text);
        if (!value) return fmt::format("'{}' is not a number", text);
        if (!(*value > 0)) return fmt::format("{} is not above 0", text);
        return std::string();
      },
      "POSITIVE", "");
}

/// A number of at least 0.
inline CLI::Validator non_negative_number() {
  return CLI::Validator(
      [](const std::string& text) {
        const auto value = wire::internal::parse_number<double>(text);
        if (!value) return fmt::format("'{}' is not a number", text);
        if (!(*value >= 0)) return fmt::format("{} is negative", text);
        return std::string();
      },
      "NONNEGATIVE", "");
}

}  // namespace rsg::app
