// GatewayStats -> the IDL `rsg::GatewayStatus` sample.
#pragma once

#include <GatewayStatus.h>

#include "rsg/gateway/stats.hpp"

namespace rsg::gateway {

/// Fills every member of `sample`; a source address longer than the IDL bound is cut.
void to_status_sample(const GatewayStats& stats, GatewayStatus& sample);

}  // namespace rsg::gateway
