// The one clock of the gateway's timing logic. Classes take `now` as an argument instead of
// reading the clock, so tests drive time explicitly.
#pragma once

#include <chrono>

namespace rsg::gateway {

using Clock = std::chrono::steady_clock;

}  // namespace rsg::gateway
