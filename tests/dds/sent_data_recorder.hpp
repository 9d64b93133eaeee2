// A UDPv4 transport that records which user samples a participant puts on the wire: the writer
// sequence numbers of the RTPS DATA submessages of user writers in every datagram it sends.
// Where a content filter is evaluated is invisible in the DDS API; this makes it countable.
#pragma once

#include <cstdint>
#include <cstring>
#include <memory>
#include <mutex>
#include <set>
#include <vector>

#include "dds/internal/transport_priority.hpp"
#include "rsg/dds/fastdds.hpp"

// The transport API is the one place of rsg's tests where Fast DDS 2 and 3 differ beyond names:
// 3.x hands a message over as a list of buffers (and renamed the headers).
#if RSG_FASTDDS_MAJOR >= 3
#include <fastdds/rtps/transport/ChainingTransport.hpp>
#include <fastdds/rtps/transport/ChainingTransportDescriptor.hpp>
#include <fastdds/rtps/transport/UDPv4TransportDescriptor.hpp>
#else
#include <fastdds/rtps/transport/ChainingTransport.h>
#include <fastdds/rtps/transport/ChainingTransportDescriptor.h>
#include <fastdds/rtps/transport/UDPv4TransportDescriptor.h>
#endif

namespace rsg::test {

namespace ftransport = eprosima::fastdds::rtps;
namespace frtps = rsg::dds::rtps;

/// The writer sequence numbers seen so far, shared between the test and Fast DDS's send threads.
class SentSamples {
 public:
  void add(std::int64_t sequence_number) {
    std::lock_guard lock(mutex_);
    sequence_numbers_.insert(sequence_number);
  }
  std::set<std::int64_t> sequence_numbers() const {
    std::lock_guard lock(mutex_);
    return sequence_numbers_;
  }

 private:
  mutable std::mutex mutex_;
  std::set<std::int64_t> sequence_numbers_;
};

/// Walks an RTPS message (RTPS 2.x, section 8.3) and reports the writer sequence number of every
/// DATA / DATA_FRAG submessage sent by a user-defined writer (entity kind without the 0xC0 bits).
inline void record_user_data(const std::uint8_t* message, std::size_t size, SentSamples& out) {
  constexpr std::size_t kHeaderBytes = 20;
  constexpr std::uint8_t kData = 0x15, kDataFrag = 0x16;
  if (size < kHeaderBytes || std::memcmp(message, "RTPS", 4) != 0) return;
  std::size_t at = kHeaderBytes;
  while (at + 4 <= size) {
    const std::uint8_t id = message[at];
    const bool little_endian = (message[at + 1] & 0x01) != 0;
    auto read32 = [&](std::size_t offset) {
      std::uint32_t value = 0;
      for (int i = 0; i < 4; ++i)
        value |= std::uint32_t{message[offset + (little_endian ? i : 3 - i)]} << (8 * i);
      return value;
    };
    const std::uint16_t length =
        little_endian ? message[at + 2] | message[at + 3] << 8 : message[at + 2] << 8 | message[at + 3];
    const std::size_t body = at + 4;
    // extraFlags(2) octetsToInlineQos(2) readerId(4) writerId(4) writerSN(high 4, low 4)
    if ((id == kData || id == kDataFrag) && body + 20 <= size) {
      const std::uint8_t writer_entity_kind = message[body + 11];
      if ((writer_entity_kind & 0xC0) == 0)
        out.add(static_cast<std::int64_t>(read32(body + 12)) << 32 | read32(body + 16));
    }
    if (length == 0) break;  // the last submessage extends to the end of the message
    at = body + length;
  }
}

/// Creates the recording transport; everything else is plain UDPv4.
struct SentDataRecordingTransportDescriptor : public ftransport::ChainingTransportDescriptor {
  explicit SentDataRecordingTransportDescriptor(std::shared_ptr<SentSamples> sent)
      : ChainingTransportDescriptor(std::make_shared<ftransport::UDPv4TransportDescriptor>()),
        sent(std::move(sent)) {}

  ftransport::TransportInterface* create_transport() const override;

  std::shared_ptr<SentSamples> sent;
};

class SentDataRecordingTransport : public ftransport::ChainingTransport {
 public:
  explicit SentDataRecordingTransport(const SentDataRecordingTransportDescriptor& descriptor)
      : ChainingTransport(descriptor), descriptor_(descriptor) {}

  ftransport::TransportDescriptorInterface* get_configuration() override { return &descriptor_; }

#if RSG_FASTDDS_MAJOR >= 3
  bool send(frtps::SenderResource* low_sender_resource, const std::vector<frtps::NetworkBuffer>& buffers,
            std::uint32_t total_bytes, frtps::LocatorsIterator* destinations_begin,
            frtps::LocatorsIterator* destinations_end,
            const std::chrono::steady_clock::time_point& timeout) override {
    std::vector<std::uint8_t> message;
    message.reserve(total_bytes);
    for (const auto& buffer : buffers) {
      const auto* bytes = static_cast<const std::uint8_t*>(buffer.buffer);
      message.insert(message.end(), bytes, bytes + buffer.size);
    }
    record_user_data(message.data(), message.size(), *descriptor_.sent);
#if RSG_FASTDDS_TRANSPORT_PRIORITY
    // Priority 0, as the deprecated send() passes; the recorder does not override send_w_priority().
    return low_sender_resource->send(buffers, total_bytes, destinations_begin, destinations_end, timeout, 0);
#else
    return low_sender_resource->send(buffers, total_bytes, destinations_begin, destinations_end, timeout);
#endif
  }
#else
  bool send(frtps::SenderResource* low_sender_resource, const frtps::octet* buffer, std::uint32_t size,
            frtps::LocatorsIterator* destinations_begin, frtps::LocatorsIterator* destinations_end,
            const std::chrono::steady_clock::time_point& timeout) override {
    record_user_data(buffer, size, *descriptor_.sent);
    return low_sender_resource->send(buffer, size, destinations_begin, destinations_end, timeout);
  }
#endif

  void receive(ftransport::TransportReceiverInterface* next_receiver, const frtps::octet* buffer,
               std::uint32_t size, const frtps::Locator_t& local_locator,
               const frtps::Locator_t& remote_locator) override {
    next_receiver->OnDataReceived(buffer, size, local_locator, remote_locator);
  }

 private:
  SentDataRecordingTransportDescriptor descriptor_;
};

// Fast DDS takes ownership of the raw transport it asks for.
inline ftransport::TransportInterface* SentDataRecordingTransportDescriptor::create_transport() const {
  return new SentDataRecordingTransport(*this);
}

}  // namespace rsg::test
