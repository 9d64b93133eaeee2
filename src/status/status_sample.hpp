// GatewayStats -> the IDL `rsg::GatewayStatus` sample.
#pragma once

#include <GatewayStatus.h>

#include "status/stats.hpp"

namespace rsg::status {

/// Fills every member of `sample`; a source address longer than the IDL bound is cut.
void to_status_sample(const GatewayStats& stats, GatewayStatus& sample);

/// The reverse, for monitors that read the status topic.
GatewayStats from_status_sample(const GatewayStatus& sample);

}  // namespace rsg::status
