#include "rsg/wire/error.hpp"

#include <cstdarg>
#include <cstdio>

namespace rsg::wire {

FrameError::FrameError(ErrorCategory category, const char* format, ...) : category_(category) {
  va_list args;
  va_start(args, format);
  std::vsnprintf(message_.data(), message_.size(), format, args);
  va_end(args);
}

}  // namespace rsg::wire
