#include "rsg/gateway/embedded_gateway.hpp"

#include <pthread.h>
#include <spdlog/spdlog.h>

#include <atomic>
#include <stdexcept>
#include <thread>

#include "gateway/config.hpp"
#include "gateway/gateway.hpp"
#include "rsg/error.hpp"

namespace rsg::gateway {
namespace {

// Everything rsg_gateway checks before it creates anything (the writer and reader profiles are
// checked through its participant, once that exists), plus the one thing embedding needs.
gateway::GatewaySetup prepare_embedded(std::string_view yaml_config,
                                       EmbeddedGateway::SampleCallback on_sample) {
  const gateway::ConfigResult parsed = gateway::parse_gateway_config(yaml_config);
  if (!parsed) {
    const auto& error = parsed.error();
    throw InputError("embedded gateway configuration" +
                     (error.line > 0 ? ", line " + std::to_string(error.line) : std::string()) + ": " +
                     error.message);
  }
  if (!parsed.config().has_ingress())
    throw InputError("embedded gateway configuration: `listen` is required");
  gateway::GatewaySetup setup;
  try {
    setup = gateway::prepare(parsed.config());
  } catch (const InputError& error) {
    throw InputError(std::string("embedded gateway configuration: ") + error.what());
  }
  setup.ingress->on_sample = std::move(on_sample);
  return setup;
}

}  // namespace

class EmbeddedGateway::Impl {
 public:
  Impl(std::string_view yaml_config, SampleCallback on_sample)
      : setup_(prepare_embedded(yaml_config, std::move(on_sample))), gateway_(setup_) {
    thread_ = std::jthread([this] {
      // The ingress loop: rsg_gateway runs it on its main thread, the embedded gateway on this one.
      ::pthread_setname_np(::pthread_self(), "rsg-ingress");  // top -H, perf, tests find it by name
      gateway::enter_realtime_mode(setup_.config);
      try {
        gateway_.run(stop_);
      } catch (const std::exception& error) {
        spdlog::error("embedded gateway stopped: {}", error.what());
      }
    });
  }
  ~Impl() { stop(); }
  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;

  void stop() {
    stop_.store(true, std::memory_order_relaxed);
    if (thread_.joinable()) thread_.join();
  }
  transport::Endpoint local_endpoint() const { return *gateway_.ingress_endpoint(); }

 private:
  gateway::GatewaySetup setup_;
  gateway::Gateway gateway_;
  std::atomic<bool> stop_{false};
  std::jthread thread_;  // last: started once everything it uses exists
};

EmbeddedGateway::EmbeddedGateway(std::string_view yaml_config, SampleCallback on_sample)
    : impl_(std::make_unique<Impl>(yaml_config, std::move(on_sample))) {}
EmbeddedGateway::~EmbeddedGateway() = default;
EmbeddedGateway::EmbeddedGateway(EmbeddedGateway&&) noexcept = default;
EmbeddedGateway& EmbeddedGateway::operator=(EmbeddedGateway&&) noexcept = default;

transport::Endpoint EmbeddedGateway::local_endpoint() const {
  if (!impl_) throw std::logic_error("EmbeddedGateway::local_endpoint after stop()");
  return impl_->local_endpoint();
}

void EmbeddedGateway::stop() { impl_.reset(); }

}  // namespace rsg::gateway
