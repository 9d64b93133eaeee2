#include "gateway/version.hpp"

namespace rsg::gateway {

std::string_view rsg_version() { return RSG_VERSION; }

std::string_view fastdds_version() { return RSG_FASTDDS_VERSION; }

}  // namespace rsg::gateway
