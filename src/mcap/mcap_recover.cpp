#include "mcap/mcap_recover.hpp"

#include <map>
#include <optional>
#include <stdexcept>
#include <string>

#include "rsg/error.hpp"

namespace rsg::mcap {
namespace {

/// Re-registers every schema and channel with a new writer (ids may differ) and copies the messages.
class Copier final : public RecordVisitor {
 public:
  Copier(const std::filesystem::path& out, WriterOptions options) : out_(out), options_(std::move(options)) {}

  void on_header(const Header& header) override {
    options_.profile = std::string(header.profile);
    options_.library = std::string(header.library);
    writer.emplace(out_, options_);
  }
  void on_schema(const Schema& schema) override {
    if (!writer || schemas_.contains(schema.id)) return;
    schemas_[schema.id] = writer->add_schema(schema.name, schema.encoding, schema.data.bytes);
  }
  void on_channel(const Channel& channel) override {
    if (!writer || channels_.contains(channel.id)) return;
    const auto schema = schemas_.find(channel.schema_id);
    if (schema == schemas_.end()) return;  // no schema (id 0) or an unknown one: its messages are unreadable
    std::vector<std::pair<std::string, std::string>> metadata;
    for (const auto& [key, value] : channel.metadata) metadata.emplace_back(key, value);
    channels_[channel.id] =
        writer->add_channel(schema->second, channel.topic, channel.message_encoding, metadata);
  }
  bool on_message(const Message& message) override {
    const auto channel = channels_.find(message.channel_id);
    if (!writer || channel == channels_.end()) {
      ++unreadable;
      return true;
    }
    writer->write(channel->second, message.sequence, message.log_time, message.publish_time,
                  message.data.bytes);
    return true;
  }

  std::optional<Writer> writer;
  std::uint64_t unreadable = 0;

 private:
  std::filesystem::path out_;
  WriterOptions options_;
  std::map<std::uint16_t, std::uint16_t> schemas_, channels_;  // damaged file's id -> new id
};

}  // namespace

RecoverResult recover(std::span<const std::uint8_t> damaged, const std::filesystem::path& out,
                      WriterOptions options) {
  Copier copier(out, std::move(options));
  RecoverResult result;
  result.scan = scan(damaged, copier);
  if (!copier.writer) throw InputError("not an MCAP file (no header): " + result.scan.error);
  copier.writer->close();
  result.written = copier.writer->totals();
  result.unreadable = copier.unreadable;
  return result;
}

}  // namespace rsg::mcap
