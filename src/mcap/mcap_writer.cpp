#include "mcap/mcap_writer.hpp"

#include <fcntl.h>
#include <isa-l/crc.h>
#include <unistd.h>
#include <zstd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>

namespace rsg::mcap {
namespace {

// CRC-32 as MCAP uses it (zlib's); ISA-L's gzip variant continues from a previous value.
std::uint32_t crc32(std::uint32_t previous, std::span<const std::uint8_t> bytes) {
  return crc32_gzip_refl(previous, bytes.data(), bytes.size());
}

}  // namespace

/// The output file descriptor; the writer only ever appends, or cuts back to a record boundary.
class Writer::File {
 public:
  File(const std::filesystem::path& path, bool exclusive) : path_(path) {
    fd_ = ::open(path.c_str(), O_WRONLY | O_CREAT | O_CLOEXEC | (exclusive ? O_EXCL | O_NOFOLLOW : O_TRUNC),
                 0644);
    if (fd_ < 0) throw error(exclusive && errno == EEXIST ? "will not overwrite" : "cannot create");
  }
  ~File() {
    if (fd_ >= 0) ::close(fd_);
  }
  File(const File&) = delete;
  File& operator=(const File&) = delete;

  void write_all(std::span<const std::uint8_t> bytes) {
    while (!bytes.empty()) {
      const ssize_t written = ::write(fd_, bytes.data(), bytes.size());
      if (written < 0 && errno == EINTR) continue;
      if (written <= 0) {
        if (written == 0) errno = ENOSPC;
        throw error("cannot write");
      }
      bytes = bytes.subspan(static_cast<std::size_t>(written));
    }
  }

  /// Waits until the kernel has the file's data (and the size needed to read it) on the disk.
  void sync() {
    while (::fdatasync(fd_) != 0)
      if (errno != EINTR) throw error("cannot sync");
  }

  /// Drops everything from `size` on; the next write continues there.
  bool cut_to(std::uint64_t size) {
    return ::ftruncate(fd_, static_cast<off_t>(size)) == 0 &&
           ::lseek(fd_, static_cast<off_t>(size), SEEK_SET) >= 0;
  }

  void close() {
    const int fd = std::exchange(fd_, -1);
    if (::close(fd) != 0) throw error("cannot close");
  }

 private:
  WriteError error(const char* what) const {
    return WriteError(std::string(what) + " " + path_.string() + ": " + std::strerror(errno));
  }

  std::filesystem::path path_;
  int fd_ = -1;
};

struct Writer::Compressor {
  struct Free {
    void operator()(ZSTD_CCtx* context) const { ZSTD_freeCCtx(context); }
  };
  std::unique_ptr<ZSTD_CCtx, Free> context{ZSTD_createCCtx()};
};

Writer::Writer(const std::filesystem::path& path, WriterOptions options)
    : options_(std::move(options)),
      file_(std::make_unique<File>(path, options_.exclusive)),
      compressor_(std::make_unique<Compressor>()) {
  if (!compressor_->context) throw WriteError("zstd: cannot create a compression context");
  chunk_.reserve(options_.chunk_bytes + 4096);
  pending_.insert(pending_.end(), std::begin(kMagic), std::end(kMagic));
  append_record(pending_, Header{options_.profile, options_.library});
  write_pending();  // an unwritable file shows now, not after the first chunk
}

Writer::~Writer() {
  try {
    if (is_open()) close();
  } catch (const WriteError&) {
    // close() is how callers learn about errors; a destructor can only do its best.
  }
}

bool Writer::is_open() const { return file_ != nullptr; }

Schema Writer::view(const OwnedSchema& schema) {
  return {.id = schema.id, .name = schema.name, .encoding = schema.encoding, .data = {schema.data}};
}

Channel Writer::view(const OwnedChannel& channel, StringMap& metadata) {
  metadata.clear();
  for (const auto& [key, value] : channel.metadata) metadata.emplace_back(key, value);
  return {.id = channel.id,
          .schema_id = channel.schema_id,
          .topic = channel.topic,
          .message_encoding = channel.message_encoding,
          .metadata = metadata};
}

std::uint16_t Writer::add_schema(std::string_view name, std::string_view encoding,
                                 std::span<const std::uint8_t> data) {
  const auto id = static_cast<std::uint16_t>(schemas_.size() + 1);
  schemas_.push_back({id, std::string(name), std::string(encoding), {data.begin(), data.end()}});
  append_record(chunk_, view(schemas_.back()));
  chunk_definitions_.emplace_back(true, schemas_.size() - 1);
  return id;
}

std::uint16_t Writer::add_channel(std::uint16_t schema_id, std::string_view topic,
                                  std::string_view message_encoding,
                                  const std::vector<std::pair<std::string, std::string>>& metadata) {
  if (schema_id == 0 || schema_id > schemas_.size()) throw std::logic_error("add_channel: unknown schema id");
  const auto id = static_cast<std::uint16_t>(channels_.size() + 1);
  channels_.push_back({id, schema_id, std::string(topic), std::string(message_encoding), metadata});
  StringMap map;
  append_record(chunk_, view(channels_.back(), map));
  chunk_definitions_.emplace_back(false, channels_.size() - 1);
  chunk_index_.resize(id + 1);
  return id;
}

void Writer::write(std::uint16_t channel_id, std::uint32_t sequence, std::uint64_t log_time,
                   std::uint64_t publish_time, std::span<const std::uint8_t> data) {
  if (!is_open()) throw WriteError("write after close");
  if (channel_id == 0 || channel_id > channels_.size()) throw std::logic_error("write: unknown channel id");
  if (chunk_messages_ == 0) chunk_start_ = chunk_end_ = log_time;
  chunk_start_ = std::min(chunk_start_, log_time);
  chunk_end_ = std::max(chunk_end_, log_time);
  chunk_index_[channel_id].emplace_back(log_time, chunk_.size());
  append_record(chunk_, Message{channel_id, sequence, log_time, publish_time, {data}});
  ++chunk_messages_;
  if (chunk_.size() >= options_.chunk_bytes || chunk_end_ - chunk_start_ >= options_.chunk_span_ns)
    finish_chunk();
}

void Writer::finish_chunk_if_older(std::uint64_t now_ns) {
  if (chunk_messages_ > 0 && now_ns >= chunk_start_ && now_ns - chunk_start_ >= options_.chunk_span_ns)
    finish_chunk();
}

void Writer::finish_chunk() {
  if (!is_open() || chunk_messages_ == 0) return;
  std::span<const std::uint8_t> records = chunk_;
  std::string_view compression;  // "" is no compression
  if (options_.compress) {
    compressed_.resize(ZSTD_compressBound(chunk_.size()));
    const std::size_t size =
        ZSTD_compressCCtx(compressor_->context.get(), compressed_.data(), compressed_.size(), chunk_.data(),
                          chunk_.size(), options_.zstd_level);
    if (ZSTD_isError(size)) fail(WriteError(std::string("zstd: ") + ZSTD_getErrorName(size)));
    records = {compressed_.data(), size};
    compression = "zstd";
  }

  ChunkIndex index{.message_start_time = chunk_start_,
                   .message_end_time = chunk_end_,
                   .chunk_start_offset = written_ + pending_.size(),
                   .compression = compression,
                   .compressed_size = records.size(),
                   .uncompressed_size = chunk_.size()};
  index.chunk_length = append_record(pending_, Chunk{.message_start_time = chunk_start_,
                                                     .message_end_time = chunk_end_,
                                                     .uncompressed_size = chunk_.size(),
                                                     .uncompressed_crc = crc32(0, chunk_),
                                                     .compression = compression,
                                                     .records = {records}});
  const std::uint64_t indexes_start = written_ + pending_.size();
  for (std::uint16_t id = 1; id < chunk_index_.size(); ++id) {
    if (chunk_index_[id].empty()) continue;
    index.message_index_offsets.emplace_back(id, written_ + pending_.size());
    append_record(pending_, MessageIndex{id, chunk_index_[id]});
  }
  index.message_index_length = written_ + pending_.size() - indexes_start;
  write_pending();

  // Only now is the chunk in the file: count it (and the schemas and channels it carries).
  for (const auto& [is_schema, index] : chunk_definitions_)
    (is_schema ? schemas_[index].in_file : channels_[index].in_file) = true;
  chunk_definitions_.clear();
  for (std::uint16_t id = 1; id < chunk_index_.size(); ++id) {
    channels_[id - 1].messages += chunk_index_[id].size();
    chunk_index_[id].clear();
  }
  if (chunk_indexes_.empty()) first_time_ = chunk_start_;
  first_time_ = std::min(first_time_, chunk_start_);
  last_time_ = std::max(last_time_, chunk_end_);
  chunk_indexes_.push_back(std::move(index));
  totals_.messages += chunk_messages_;
  totals_.chunks += 1;
  totals_.uncompressed_bytes += chunk_.size();
  totals_.compressed_bytes += records.size();
  chunk_.clear();
  chunk_messages_ = 0;
  sync_if_asked();  // after the bookkeeping: should it fail, the summary fail() writes holds this chunk
}

void Writer::sync_if_asked() {
  if (!options_.sync) return;
  const auto start = std::chrono::steady_clock::now();
  try {
    file_->sync();
  } catch (const WriteError& error) {
    if (failing_) throw;
    fail(error);
  }
  totals_.syncs += 1;
  totals_.sync_ns += static_cast<std::uint64_t>(
      std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now() - start).count());
}

void Writer::write_pending() {
  if (pending_.empty()) return;
  try {
    file_->write_all(pending_);
  } catch (const WriteError& error) {
    if (failing_) throw;
    fail(error);
  }
  data_crc_ = crc32(data_crc_, pending_);
  written_ += pending_.size();
  totals_.file_bytes = written_;
  pending_.clear();
}

void Writer::fail(const WriteError& error) {
  // Cut the file back to its last whole record, then try to end it properly in the space that
  // frees: a file with a summary is better than one that only a scanning reader can read.
  failing_ = true;
  pending_.clear();
  chunk_.clear();
  chunk_definitions_.clear();
  chunk_messages_ = 0;
  for (auto& entries : chunk_index_) entries.clear();
  // Without room for the summary, a footer alone (50 bytes) still makes the file complete.
  std::string outcome = "; the file is readable up to its last finished chunk by a reader that scans it";
  bool finished = false;
  for (const bool with_summary : {true, false}) {
    if (!file_->cut_to(written_)) break;
    try {
      write_summary_and_footer(with_summary);
      file_->close();
      outcome = with_summary
                    ? "; the file was finished with what was recorded up to its last finished chunk"
                    : "; the file was finished without an index, with what was recorded up to its last "
                      "finished chunk";
      finished = true;
      break;
    } catch (const WriteError&) {
      pending_.clear();
    }
  }
  if (!finished) file_->cut_to(written_);
  file_.reset();
  throw WriteError(error.what() + outcome);
}

void Writer::write_summary_and_footer(bool with_summary) {
  // Schemas and channels that no written chunk carries (no message came, or a write failed before
  // their chunk was whole) go into the data section on their own: the summary repeats only what
  // the data section has.
  chunk_.clear();
  chunk_definitions_.clear();
  StringMap map;
  for (auto& schema : schemas_)
    if (!std::exchange(schema.in_file, true)) append_record(pending_, view(schema));
  for (auto& channel : channels_)
    if (!std::exchange(channel.in_file, true)) append_record(pending_, view(channel, map));
  write_pending();
  append_record(pending_, DataEnd{crc32(data_crc_, pending_)});
  if (!with_summary) {
    append_record(pending_, Footer{});
    pending_.insert(pending_.end(), std::begin(kMagic), std::end(kMagic));
    write_pending();
    return;
  }
  const std::uint64_t summary_start = written_ + pending_.size();

  std::vector<SummaryOffset> groups;
  const auto group = [&](Opcode opcode, auto&& append_all) {
    const std::uint64_t start = written_ + pending_.size();
    append_all();
    const std::uint64_t length = written_ + pending_.size() - start;
    if (length > 0) groups.push_back({static_cast<std::uint8_t>(opcode), start, length});
  };
  group(Opcode::schema, [&] {
    for (const auto& schema : schemas_) append_record(pending_, view(schema));
  });
  group(Opcode::channel, [&] {
    StringMap map;
    for (const auto& channel : channels_) append_record(pending_, view(channel, map));
  });
  group(Opcode::statistics, [&] {
    Statistics statistics{.message_count = totals_.messages,
                          .schema_count = static_cast<std::uint16_t>(schemas_.size()),
                          .channel_count = static_cast<std::uint32_t>(channels_.size()),
                          .chunk_count = static_cast<std::uint32_t>(chunk_indexes_.size()),
                          .message_start_time = first_time_,
                          .message_end_time = last_time_};
    for (const auto& channel : channels_)
      statistics.channel_message_counts.emplace_back(channel.id, channel.messages);
    append_record(pending_, statistics);
  });
  group(Opcode::chunk_index, [&] {
    for (const auto& index : chunk_indexes_) append_record(pending_, index);
  });

  const std::uint64_t summary_offset_start = written_ + pending_.size();
  for (const auto& offset : groups) append_record(pending_, offset);
  append_record(pending_, Footer{summary_start, summary_offset_start, 0});
  // The summary CRC covers the summary up to and including the footer's summary_offset_start.
  const std::size_t crc_from = static_cast<std::size_t>(summary_start - written_);
  const std::uint32_t summary_crc =
      crc32(0, std::span<const std::uint8_t>(pending_).subspan(crc_from, pending_.size() - crc_from - 4));
  for (std::size_t i = 0; i < 4; ++i)
    pending_[pending_.size() - 4 + i] = static_cast<std::uint8_t>(summary_crc >> (8 * i));
  pending_.insert(pending_.end(), std::begin(kMagic), std::end(kMagic));
  write_pending();
}

void Writer::close() {
  if (!is_open()) return;
  finish_chunk();
  write_summary_and_footer(/*with_summary=*/true);
  sync_if_asked();
  try {
    file_->close();
  } catch (const WriteError&) {
    file_.reset();
    throw;
  }
  file_.reset();
}

}  // namespace rsg::mcap
