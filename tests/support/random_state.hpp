// Random frames for property tests: any selection, any bit pattern a valid frame may carry.
#pragma once

#include <bit>
#include <cmath>
#include <random>

#include "rsg/wire/error_flags.hpp"
#include "rsg/wire/state_values.hpp"

namespace rsg::test {

inline double random_double(std::mt19937_64& rng, bool allow_nan_payloads) {
  switch (rng() % 6) {
    case 0: {
      const double value = std::bit_cast<double>(rng());  // any pattern: NaN payloads, denormals
      if (!allow_nan_payloads && std::isnan(value)) return std::numeric_limits<double>::quiet_NaN();
      return value;
    }
    case 1:
      return -0.0;
    case 2:
      return std::uniform_real_distribution<double>(-10, 10)(rng);
    case 3:
      return static_cast<double>(static_cast<int>(rng() % 200) - 100) / 8.0;
    case 4:
      return std::ldexp(1.0, static_cast<int>(rng() % 2000) - 1000);
    default:
      return std::numeric_limits<double>::infinity() * ((rng() & 1) ? 1 : -1);
  }
}

inline wire::StateValues random_state(std::mt19937_64& rng, bool allow_nan_payloads = true) {
  wire::StateValues values;
  values.packet_number = static_cast<std::uint8_t>(rng() % 16);
  for (std::size_t group = 0; group < wire::kGroupCount; ++group) {
    if (rng() % 4 == 0) continue;
    values.selection.group_select |= static_cast<std::uint8_t>(1U << group);
    values.selection.data_select[group] = static_cast<std::uint8_t>(rng());
  }
  values.selection.data_select[5] &= 0x0F;
  for (const wire::FieldInfo& field : wire::kFields) {
    if (!values.selection.contains(field.id())) continue;
    switch (field.type) {
      case wire::ElementType::kFloat64:
        for (double& element : values.doubles(field.id())) element = random_double(rng, allow_nan_payloads);
        break;
      case wire::ElementType::kErrorSet:
        values.set_integer(field.id(), rng() & ~(~std::uint64_t{0} << wire::kErrorFlagCount));
        break;
      case wire::ElementType::kUInt8:
        values.set_integer(field.id(), rng() % (wire::kMaxRobotMode + 1));
        break;
      case wire::ElementType::kUInt64:
        values.set_integer(field.id(), rng());
        break;
    }
  }
  return values;
}

}  // namespace rsg::test
