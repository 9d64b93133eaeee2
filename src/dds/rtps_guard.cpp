#include "dds/internal/rtps_guard.hpp"

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "dds/internal/rtps_screen.hpp"
#include "dds/internal/spdp_admission.hpp"
#include "dds/internal/transport_priority.hpp"
#include "rsg/dds/fastdds.hpp"
#include "rsg/error.hpp"

// The transport API is where Fast DDS 2 and 3 differ beyond names: 3.x hands a message over as a
// list of buffers, renamed the headers and sets up its built-in transports itself.
#if RSG_FASTDDS_MAJOR >= 3
#include <fastdds/rtps/attributes/BuiltinTransports.hpp>
#include <fastdds/rtps/common/LocatorList.hpp>
#include <fastdds/rtps/common/LocatorSelector.hpp>
#include <fastdds/rtps/transport/ChainingTransport.hpp>
#include <fastdds/rtps/transport/ChainingTransportDescriptor.hpp>
#include <fastdds/rtps/transport/UDPv4TransportDescriptor.hpp>
#include <fastdds/rtps/transport/UDPv6TransportDescriptor.hpp>
#include <fastdds/rtps/transport/shared_mem/SharedMemTransportDescriptor.hpp>
#else
#include <fastdds/rtps/transport/ChainingTransport.h>
#include <fastdds/rtps/transport/ChainingTransportDescriptor.h>
#include <fastdds/rtps/transport/UDPv4TransportDescriptor.h>
#include <fastdds/rtps/transport/UDPv6TransportDescriptor.h>
#include <fastdds/rtps/transport/shared_mem/SharedMemTransportDescriptor.h>

#include <fastdds/rtps/common/LocatorList.hpp>
#include <fastdds/rtps/common/LocatorSelector.hpp>
#endif

namespace rsg::dds::internal {
namespace {

namespace ftransport = eprosima::fastdds::rtps;
using Locator = rtps::Locator_t;

struct GuardDescriptor : public ftransport::ChainingTransportDescriptor {
  GuardDescriptor(std::shared_ptr<ftransport::TransportDescriptorInterface> low_level,
                  std::shared_ptr<RtpsGuardCounts> counts, std::shared_ptr<SpdpAdmission> admission)
      : ChainingTransportDescriptor(std::move(low_level)),
        counts(std::move(counts)),
        admission(std::move(admission)) {}

  ftransport::TransportInterface* create_transport() const override;

  std::shared_ptr<RtpsGuardCounts> counts;
  std::shared_ptr<SpdpAdmission> admission;  // one per participant, whichever transport receives
};

/// Calls `visit` with each destination of a send, on a copy of the caller's iterator (the low-level
/// transport advances the one it is given). Fast DDS passes one of its two concrete iterators;
/// false for any other, whose destinations are then not looked at.
template <class Iterator, class Visit>
bool visit_destinations_as(rtps::LocatorsIterator* begin, rtps::LocatorsIterator* end, Visit&& visit) {
  auto* first = dynamic_cast<Iterator*>(begin);
  auto* last = dynamic_cast<Iterator*>(end);
  if (first == nullptr || last == nullptr) return false;
  for (Iterator at(*first); at != *last; ++at) visit(*at);
  return true;
}

template <class Visit>
void visit_destinations(rtps::LocatorsIterator* begin, rtps::LocatorsIterator* end, Visit&& visit) {
  visit_destinations_as<rtps::Locators>(begin, end, visit) ||
      visit_destinations_as<rtps::LocatorSelector::iterator>(begin, end, visit);
}

constexpr std::uint32_t kRtpsHeaderBytes = 20;

/// UDP behind the guard. Receiving: every datagram screened (rtps_screen.hpp): what fails a check
/// and a statistics submessage are cut off, a datagram with nothing valid left is dropped.
/// Sending: Fast DDS before 2.14.5 / 3.1.3 sends to a reader locator it opened no output channel
/// for when a reader announces both unicast and multicast locators, and the UDP transport's
/// statistics then assert (OutputTrafficManager::set_statistics_message_data) or read end() in a
/// release build. The guard opens the channel first, which records the locator, as the upstream fix
/// (Fast-DDS PR 5704) does.
class GuardTransport final : public ftransport::ChainingTransport {
 public:
  explicit GuardTransport(const GuardDescriptor& descriptor)
      : ChainingTransport(descriptor),
        descriptor_(descriptor),
        counts_(*descriptor_.counts),
        admission_(*descriptor_.admission) {
    rewritten_.reserve(kMaxDatagramBytes);
  }

  ftransport::TransportDescriptorInterface* get_configuration() override { return &descriptor_; }

  bool OpenOutputChannel(ftransport::SendResourceList& sender_resource_list,
                         const Locator& locator) override {
    std::lock_guard lock(mutex_);
    const bool opened = ChainingTransport::OpenOutputChannel(sender_resource_list, locator);
    if (opened) opened_.insert(locator);
    return opened;
  }

#if RSG_FASTDDS_MAJOR >= 3
  bool send(rtps::SenderResource* low_sender_resource, const std::vector<rtps::NetworkBuffer>& buffers,
            std::uint32_t total_bytes, rtps::LocatorsIterator* destinations_begin,
            rtps::LocatorsIterator* destinations_end,
            const std::chrono::steady_clock::time_point& timeout) override {
    // Priority 0: what SenderResource's send without a priority passes on (Fast DDS 3.4 and later).
    return send_guarded(low_sender_resource, buffers, total_bytes, destinations_begin, destinations_end,
                        timeout, 0);
  }
#if RSG_FASTDDS_TRANSPORT_PRIORITY
  // What Fast DDS calls from 3.4 on: the writer's TransportPriorityQosPolicy reaches the low-level
  // transport through the guard as it would without it (ChainingTransport's default drops it).
  bool send_w_priority(rtps::SenderResource* low_sender_resource,
                       const std::vector<rtps::NetworkBuffer>& buffers, std::uint32_t total_bytes,
                       rtps::LocatorsIterator* destinations_begin, rtps::LocatorsIterator* destinations_end,
                       const std::chrono::steady_clock::time_point& timeout, std::int32_t priority) override {
    return send_guarded(low_sender_resource, buffers, total_bytes, destinations_begin, destinations_end,
                        timeout, priority);
  }
#endif
#else
  bool send(rtps::SenderResource* low_sender_resource, const rtps::octet* buffer, std::uint32_t size,
            rtps::LocatorsIterator* destinations_begin, rtps::LocatorsIterator* destinations_end,
            const std::chrono::steady_clock::time_point& timeout) override {
    if (auto reachable = open_missing_channels(destinations_begin, destinations_end)) {
      rtps::Locators first(reachable->cbegin()), last(reachable->cend());
      return low_sender_resource->send(buffer, size, &first, &last, timeout);
    }
    return low_sender_resource->send(buffer, size, destinations_begin, destinations_end, timeout);
  }
#endif

  void receive(ftransport::TransportReceiverInterface* next_receiver, const rtps::octet* buffer,
               std::uint32_t size, const Locator& local_locator, const Locator& remote_locator) override {
    const RtpsScreen screen = screen_rtps_datagram(buffer, size);
    switch (screen.cut) {
      case RtpsScreen::Cut::kNone:
        break;
      case RtpsScreen::Cut::kTrailing:
        counts_.statistics_removed.fetch_add(1, std::memory_order_relaxed);
        break;
      case RtpsScreen::Cut::kMisplaced:
        counts_.statistics_misplaced.fetch_add(1, std::memory_order_relaxed);
        break;
      case RtpsScreen::Cut::kInvalid:
        counts_.screened_out[static_cast<std::size_t>(screen.reason)].fetch_add(1, std::memory_order_relaxed);
        break;
    }
    if (screen.forward_bytes <= kRtpsHeaderBytes) return;  // nothing Fast DDS may read is left
    AnnouncementSource source;
    std::copy(std::begin(remote_locator.address), std::end(remote_locator.address), source.address.begin());
    source.port = remote_locator.port;
    const auto decision = admission_.admit(buffer, screen.forward_bytes, source, SpdpAdmission::Clock::now());
    switch (decision.verdict) {
      case SpdpAdmission::Verdict::kPass:
        break;
      case SpdpAdmission::Verdict::kRefuse:
        counts_.announcements_refused.fetch_add(1, std::memory_order_relaxed);
        return;
      case SpdpAdmission::Verdict::kShortLease:
        if (shorten_lease(next_receiver, buffer, screen.forward_bytes, decision, local_locator,
                          remote_locator))
          return;
        break;
    }
    next_receiver->OnDataReceived(buffer, screen.forward_bytes, local_locator, remote_locator);
  }

 private:
#if RSG_FASTDDS_MAJOR >= 3
  bool send_guarded(rtps::SenderResource* low_sender_resource,
                    const std::vector<rtps::NetworkBuffer>& buffers, std::uint32_t total_bytes,
                    rtps::LocatorsIterator* destinations_begin, rtps::LocatorsIterator* destinations_end,
                    const std::chrono::steady_clock::time_point& timeout,
                    [[maybe_unused]] std::int32_t priority) {
    auto low_send = [&](rtps::LocatorsIterator* begin, rtps::LocatorsIterator* end) {
#if RSG_FASTDDS_TRANSPORT_PRIORITY
      return low_sender_resource->send(buffers, total_bytes, begin, end, timeout, priority);
#else
      return low_sender_resource->send(buffers, total_bytes, begin, end, timeout);
#endif
    };
    if (auto reachable = open_missing_channels(destinations_begin, destinations_end)) {
      rtps::Locators first(reachable->cbegin()), last(reachable->cend());
      return low_send(&first, &last);
    }
    return low_send(destinations_begin, destinations_end);
  }
#endif

  /// Hands on an announcement of a participant on probation with its lease cut to
  /// kProbationLease, from a copy (the received buffer is Fast DDS's, and read-only). False when
  /// the lease is short enough already: the caller hands on the original.
  bool shorten_lease(ftransport::TransportReceiverInterface* next_receiver, const rtps::octet* buffer,
                     std::uint32_t size, const SpdpAdmission::Decision& decision,
                     const Locator& local_locator, const Locator& remote_locator) {
    const std::uint32_t at = decision.lease_at;
    const auto read32 = [&](std::uint32_t offset) {
      const rtps::octet* b = buffer + offset;
      return decision.lease_little_endian ? std::uint32_t{b[0]} | std::uint32_t{b[1]} << 8 |
                                                std::uint32_t{b[2]} << 16 | std::uint32_t{b[3]} << 24
                                          : std::uint32_t{b[3]} | std::uint32_t{b[2]} << 8 |
                                                std::uint32_t{b[1]} << 16 | std::uint32_t{b[0]} << 24;
    };
    const auto limit = static_cast<std::int32_t>(kProbationLease.count());
    const auto seconds = static_cast<std::int32_t>(read32(at));
    if (seconds >= 0 && seconds < limit) return false;
    std::lock_guard lock(rewrite_mutex_);
    rewritten_.assign(buffer, buffer + size);
    for (int i = 0; i < 4; ++i) {
      const int shift = decision.lease_little_endian ? 8 * i : 8 * (3 - i);
      rewritten_[at + i] = static_cast<rtps::octet>(static_cast<std::uint32_t>(limit) >> shift);
      rewritten_[at + 4 + i] = 0;  // no fraction
    }
    counts_.leases_shortened.fetch_add(1, std::memory_order_relaxed);
    next_receiver->OnDataReceived(rewritten_.data(), size, local_locator, remote_locator);
    return true;
  }

  /// Opens a channel for every destination that has none. Returns the destinations to send to
  /// when one of them could not be opened (a rare path: it allocates), else nothing.
  std::optional<std::vector<Locator>> open_missing_channels(rtps::LocatorsIterator* begin,
                                                            rtps::LocatorsIterator* end) {
    std::lock_guard lock(mutex_);
    bool any_unreachable = false;
    visit_destinations(begin, end, [&](const Locator& destination) {
      if (!low_level_transport_->IsLocatorSupported(destination) || opened_.count(destination) != 0) return;
      ftransport::SendResourceList scratch;  // the sockets it may open are not needed: closed at once
      if (low_level_transport_->OpenOutputChannel(scratch, destination)) {
        opened_.insert(destination);
        counts_.send_channels_opened.fetch_add(1, std::memory_order_relaxed);
      } else {
        any_unreachable = true;
      }
    });
    if (!any_unreachable) return std::nullopt;
    std::vector<Locator> reachable;
    visit_destinations(begin, end, [&](const Locator& destination) {
      if (opened_.count(destination) != 0 || !low_level_transport_->IsLocatorSupported(destination)) {
        reachable.push_back(destination);
      } else {
        counts_.destinations_skipped.fetch_add(1, std::memory_order_relaxed);
      }
    });
    return reachable;
  }

  static constexpr std::size_t kMaxDatagramBytes = 65536;

  GuardDescriptor descriptor_;
  RtpsGuardCounts& counts_;
  SpdpAdmission& admission_;
  std::mutex rewrite_mutex_;            // receive threads of this transport's sockets
  std::vector<rtps::octet> rewritten_;  // reserved once: an announcement never exceeds a datagram
  std::mutex mutex_;
  std::set<Locator> opened_;  // every locator the low-level transport opened a channel for
};

// Fast DDS takes ownership of the raw transport it asks for.
ftransport::TransportInterface* GuardDescriptor::create_transport() const {
  return new GuardTransport(*this);
}

bool is_udp(const ftransport::TransportDescriptorInterface& descriptor) {
  return dynamic_cast<const ftransport::UDPv4TransportDescriptor*>(&descriptor) != nullptr ||
         dynamic_cast<const ftransport::UDPv6TransportDescriptor*>(&descriptor) != nullptr;
}

#if RSG_FASTDDS_MAJOR >= 3
/// Fast DDS 3 reads FASTDDS_BUILTIN_TRANSPORTS when it sets up its built-ins; rsg does it first, the
/// same way, so that the UDP ones can be guarded.
rtps::BuiltinTransports builtin_transports_from_environment() {
  const char* value = std::getenv("FASTDDS_BUILTIN_TRANSPORTS");
  if (value == nullptr || *value == '\0') return rtps::BuiltinTransports::DEFAULT;
  const std::string name(value);
  using B = rtps::BuiltinTransports;
  for (const auto& [known, kind] : {std::pair{"NONE", B::NONE},
                                    {"DEFAULT", B::DEFAULT},
                                    {"DEFAULTv6", B::DEFAULTv6},
                                    {"SHM", B::SHM},
                                    {"UDPv4", B::UDPv4},
                                    {"UDPv6", B::UDPv6},
                                    {"LARGE_DATA", B::LARGE_DATA},
                                    {"LARGE_DATAv6", B::LARGE_DATAv6}}) {
    if (name == known) return kind;
  }
  throw InputError(
      "FASTDDS_BUILTIN_TRANSPORTS=" + name +
      ": rsg takes NONE, DEFAULT, DEFAULTv6, SHM, UDPv4, UDPv6, LARGE_DATA or LARGE_DATAv6 (no options)");
}
#endif

/// The transports Fast DDS would build in, as explicit descriptors.
void make_builtins_explicit(eprosima::fastdds::dds::DomainParticipantQos& qos) {
#if RSG_FASTDDS_MAJOR >= 3
  qos.setup_transports(builtin_transports_from_environment());
#else
  // As RTPSParticipantImpl's constructor builds them (2.9 to 2.14).
  auto& transport = qos.transport();
  auto udp = std::make_shared<ftransport::UDPv4TransportDescriptor>();
  udp->sendBufferSize = transport.send_socket_buffer_size;
  udp->receiveBufferSize = transport.listen_socket_buffer_size;
  auto shm = std::make_shared<ftransport::SharedMemTransportDescriptor>();
  shm->segment_size(std::max(transport.send_socket_buffer_size, transport.listen_socket_buffer_size) * 2);
  shm->max_message_size(udp->max_message_size());
  transport.user_transports.push_back(udp);
  transport.user_transports.push_back(shm);
  transport.use_builtin_transports = false;
#endif
}

}  // namespace

void guard_transports(eprosima::fastdds::dds::DomainParticipantQos& qos,
                      std::shared_ptr<RtpsGuardCounts> counts) {
  if (qos.transport().use_builtin_transports) make_builtins_explicit(qos);
  auto admission = std::make_shared<SpdpAdmission>();
  for (auto& descriptor : qos.transport().user_transports) {
    if (descriptor && is_udp(*descriptor))
      descriptor = std::make_shared<GuardDescriptor>(descriptor, counts, admission);
  }
}

void bound_discovery(eprosima::fastdds::dds::DomainParticipantQos& qos) {
  auto& allocation = qos.allocation();
  constexpr auto unbounded = std::numeric_limits<std::size_t>::max();
  if (allocation.participants.maximum == unbounded) allocation.participants.maximum = kMaxRemoteParticipants;
  if (allocation.readers.maximum == unbounded) allocation.readers.maximum = kMaxEndpointsPerRemoteParticipant;
  if (allocation.writers.maximum == unbounded) allocation.writers.maximum = kMaxEndpointsPerRemoteParticipant;
  auto& limits = allocation.data_limits;  // 0: unbounded
  if (limits.max_user_data == 0) limits.max_user_data = kMaxAnnouncedUserDataBytes;
  if (limits.max_partitions == 0) limits.max_partitions = kMaxAnnouncedPartitionBytes;
  if (limits.max_properties == 0) limits.max_properties = kMaxAnnouncedPropertyBytes;
}

}  // namespace rsg::dds::internal
