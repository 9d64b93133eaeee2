// FUZZ_REQUIRE: the property checks of the fuzz targets. Unlike assert() it stays on in optimised
// builds, and it names the broken property before aborting so libFuzzer saves the input.
#pragma once

#include <cstdio>
#include <cstdlib>

namespace rsg::fuzz {

[[noreturn]] inline void property_failed(const char* property, const char* file, int line) {
  std::fprintf(stderr, "%s:%d: property violated: %s\n", file, line, property);
  std::abort();
}

}  // namespace rsg::fuzz

#define FUZZ_REQUIRE(property) \
  ((property) ? static_cast<void>(0) : ::rsg::fuzz::property_failed(#property, __FILE__, __LINE__))
