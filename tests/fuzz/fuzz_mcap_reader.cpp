// rsg_replay's MCAP reader on arbitrary bytes. Besides not crashing (every view it hands out is
// read in full, so ASan sees any that points outside its buffer), it must read a cut-off file as
// a prefix of the whole one: a killed recorder's file never yields a message the whole file lacks.
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "mcap/mcap_reader.hpp"
#include "tests/fuzz/fuzz_check.hpp"

namespace {

std::uint64_t digest(std::span<const std::uint8_t> bytes) {
  std::uint64_t hash = 1469598103934665603ull;  // FNV-1a
  for (const std::uint8_t byte : bytes) hash = (hash ^ byte) * 1099511628211ull;
  return hash;
}
std::uint64_t digest(std::string_view text) {
  return digest({reinterpret_cast<const std::uint8_t*>(text.data()), text.size()});
}

struct Digests : rsg::mcap::RecordVisitor {
  std::vector<std::uint64_t> messages;
  std::uint64_t other = 0;
  void on_schema(const rsg::mcap::Schema& schema) override {
    other ^= digest(schema.name) ^ digest(schema.encoding) ^ digest(schema.data.bytes);
  }
  void on_channel(const rsg::mcap::Channel& channel) override {
    other ^= digest(channel.topic) ^ digest(channel.message_encoding);
    for (const auto& [key, value] : channel.metadata) other ^= digest(key) ^ digest(value);
  }
  bool on_message(const rsg::mcap::Message& message) override {
    messages.push_back(digest(message.data.bytes) ^ message.channel_id ^ message.sequence ^ message.log_time ^
                       message.publish_time);
    return true;
  }
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  // Small chunks only: a claimed size is allocated before it is checked against the content.
  const rsg::mcap::ReadLimits limits{.max_chunk_bytes = 1 << 20};
  const std::span<const std::uint8_t> file(data, size);
  Digests whole;
  const rsg::mcap::ScanResult result = rsg::mcap::scan(file, whole, limits);
  FUZZ_REQUIRE(result.offset <= size);
  FUZZ_REQUIRE(result.messages == whole.messages.size());
  FUZZ_REQUIRE(result.status != rsg::mcap::ScanResult::Status::stopped);

  const std::size_t cut = size / 2;
  Digests part;
  const rsg::mcap::ScanResult cut_result = rsg::mcap::scan(file.first(cut), part, limits);
  FUZZ_REQUIRE(part.messages.size() <= whole.messages.size());
  FUZZ_REQUIRE(std::equal(part.messages.begin(), part.messages.end(), whole.messages.begin()));
  if (cut_result.status == rsg::mcap::ScanResult::Status::complete)
    FUZZ_REQUIRE(part.messages == whole.messages);
  return 0;
}
