// An MCAP file writer: chunked, zstd-compressed, indexed (message indexes after every chunk, and a
// summary with schemas, channels, statistics and chunk indexes), so that viewers can seek.
//
//   rsg::mcap::Writer writer("run.mcap", {.profile = ""});
//   auto schema = writer.add_schema("rsg::RobotState", "omgidl", idl_text);
//   auto channel = writer.add_channel(schema, "robot_state", "cdr", {});
//   writer.write(channel, sequence, log_time_ns, publish_time_ns, cdr_bytes);
//   writer.close();  // or let the destructor finish the file
//
// Crash safety: a schema or channel goes into the open chunk, ahead of the messages that use it (as
// MCAP's own writers do; `mcap recover` copies such chunks as they are), and every finished chunk goes to the
// kernel at once (write(2)), so a writer killed with SIGKILL leaves a file that a reader scanning records
// front to back can read up to its last finished chunk (with `sync`, a machine that loses power too). When a
// write fails (disk full, file size limit) the file is cut back to its last whole record and, where the freed
// space allows, finished with a summary; the error is then thrown.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "mcap/mcap_records.hpp"
#include "rsg/error.hpp"

namespace rsg::mcap {

/// A failed write or open; the message names the file and the system's reason.
class WriteError : public EnvironmentError {
 public:
  using EnvironmentError::EnvironmentError;
};

struct WriterOptions {
  std::string profile{};  ///< "" or a well-known profile such as "ros2"
  std::string library = "rsg";
  /// A chunk is finished when its uncompressed records reach this size ...
  std::size_t chunk_bytes = 1 << 20;
  /// ... or when its messages span this much log time, so a slow stream loses little in a crash.
  std::uint64_t chunk_span_ns = 1'000'000'000;
  bool compress = true;  ///< zstd; false writes uncompressed chunks
  int zstd_level = 3;
  /// fdatasync(2) after every finished chunk and at close: what was written survives a power loss,
  /// not only a crash of the process, at the cost of one disk flush per chunk (see WriterTotals).
  bool sync = false;
  /// Create the file only if there is none at the path (O_EXCL, and O_NOFOLLOW: a symlink planted
  /// there is not followed): a recorder never overwrites a file, its own earlier ones included.
  bool exclusive = false;
};

/// What the file holds so far (finished chunks only for the byte counts).
struct WriterTotals {
  std::uint64_t messages = 0;
  std::uint64_t chunks = 0;
  std::uint64_t uncompressed_bytes = 0;  ///< chunk records before compression
  std::uint64_t compressed_bytes = 0;    ///< the same after compression
  std::uint64_t file_bytes = 0;          ///< written to the file
  std::uint64_t syncs = 0;               ///< fdatasync calls (WriterOptions::sync)
  std::uint64_t sync_ns = 0;             ///< time spent in them, the cost of --fsync
};

class Writer {
 public:
  /// Creates (or truncates) `path` and writes the magic and the header.
  /// @throws WriteError.
  Writer(const std::filesystem::path& path, WriterOptions options);
  /// Finishes the file if close() was not called; errors are lost then, so call close() to see them.
  ~Writer();
  Writer(const Writer&) = delete;
  Writer& operator=(const Writer&) = delete;

  /// Registers a schema and writes it to the data section; returns its id (never 0).
  std::uint16_t add_schema(std::string_view name, std::string_view encoding,
                           std::span<const std::uint8_t> data);
  /// Registers a channel on a schema added before; returns its id.
  std::uint16_t add_channel(std::uint16_t schema_id, std::string_view topic,
                            std::string_view message_encoding,
                            const std::vector<std::pair<std::string, std::string>>& metadata);

  /// Adds one message to the open chunk; finishes the chunk when it is full. Messages must come in
  /// log_time order.
  /// @throws WriteError (the file is then finished as far as possible and closed).
  void write(std::uint16_t channel_id, std::uint32_t sequence, std::uint64_t log_time,
             std::uint64_t publish_time, std::span<const std::uint8_t> data);
  /// Finishes the open chunk when its first message is older than chunk_span_ns at `now_ns`: call it
  /// now and then so that a quiet stream still reaches the disk.
  void finish_chunk_if_older(std::uint64_t now_ns);
  /// Finishes the open chunk (if it has messages) and hands it to the kernel.
  void finish_chunk();
  /// Writes the last chunk, the summary and the footer, and closes the file.
  /// @throws WriteError.
  void close();

  const WriterTotals& totals() const { return totals_; }
  bool is_open() const;

 private:
  struct OwnedSchema {
    std::uint16_t id;
    std::string name, encoding;
    std::vector<std::uint8_t> data;
    bool in_file = false;  ///< a chunk that carries it (or the data section itself) is in the file
  };
  struct OwnedChannel {
    std::uint16_t id, schema_id;
    std::string topic, message_encoding;
    std::vector<std::pair<std::string, std::string>> metadata;
    std::uint64_t messages = 0;
    bool in_file = false;
  };
  class File;
  struct Compressor;

  void write_pending();
  void sync_if_asked();
  void write_summary_and_footer(bool with_summary);
  [[noreturn]] void fail(const WriteError& error);
  static Schema view(const OwnedSchema& schema);
  static Channel view(const OwnedChannel& channel, StringMap& metadata);

  WriterOptions options_;
  std::unique_ptr<File> file_;
  std::unique_ptr<Compressor> compressor_;
  std::vector<std::uint8_t> pending_;  // whole records not yet written
  std::uint64_t written_ = 0;          // file offset: every byte before it is a whole record on disk
  std::uint32_t data_crc_ = 0;         // CRC-32 of the bytes written so far (the data section)
  bool failing_ = false;               // fail() is ending the file after a write error

  std::vector<OwnedSchema> schemas_;
  std::vector<OwnedChannel> channels_;

  // The open chunk: its records, and per channel the (log_time, offset) of each message in it.
  std::vector<std::uint8_t> chunk_;
  std::vector<std::pair<bool, std::size_t>>
      chunk_definitions_;                 // (schema?, index): what the open chunk carries
  std::vector<TimeOffsets> chunk_index_;  // indexed by channel id
  std::uint64_t chunk_start_ = 0, chunk_end_ = 0;
  std::uint64_t chunk_messages_ = 0;
  std::vector<std::uint8_t> compressed_;

  std::vector<ChunkIndex> chunk_indexes_;  // their compression names are string literals
  std::uint64_t first_time_ = 0, last_time_ = 0;
  WriterTotals totals_;
};

}  // namespace rsg::mcap
