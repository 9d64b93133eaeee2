// The gateway's YAML configuration comes from operators and deployment tools: any text must give
// a configuration or a located error, never a crash, an exception or a hang.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "gateway/config.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const rsg::gateway::ConfigResult result = rsg::gateway::parse_gateway_config(text);
  if (!result) {
    if (result.error().message.empty()) __builtin_trap();  // every rejection must say why
    return 0;
  }
  // A parsed configuration must survive the combination checks the gateway runs next.
  if (!rsg::gateway::check_config(result.config())) (void)rsg::gateway::requested_selection(result.config());
  return 0;
}
