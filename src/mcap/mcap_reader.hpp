// Reads an MCAP file front to back, record by record, without its summary: the way to read a file
// whose recorder was killed (no summary, maybe a half-written last chunk), and what rsg_replay uses.
//
// The bytes come from outside: every length is checked against what is left, chunks are
// decompressed only up to a size limit and their CRC checked, and a damaged file gives a status
// naming the offset and the problem, never a crash (fuzzed by tests/fuzz/fuzz_mcap_reader.cpp).
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "mcap/mcap_records.hpp"

namespace rsg::mcap {

/// What a scan meets, in file order. Views are valid during the call only.
class RecordVisitor {
 public:
  virtual ~RecordVisitor() = default;
  /// The file's Header record, before anything else.
  virtual void on_header(const Header&) {}
  virtual void on_schema(const Schema&) {}
  virtual void on_channel(const Channel&) {}
  /// Return false to stop the scan (status `stopped`).
  virtual bool on_message(const Message&) { return true; }
};

struct ScanResult {
  enum class Status {
    complete,   ///< reached the Data End record or the footer
    truncated,  ///< the file ends inside a record or before its end: a killed recorder's file
    malformed,  ///< not MCAP, or a record that breaks the spec (bad CRC, bad lengths, ...)
    stopped,    ///< the visitor asked to stop
  };
  Status status = Status::complete;
  std::string error;         ///< what is wrong, for truncated and malformed
  std::uint64_t offset = 0;  ///< where in the file (of the chunk, for problems inside one)
  std::uint64_t messages = 0;
  std::uint64_t chunks = 0;

  bool readable() const { return status == Status::complete || status == Status::stopped; }
};

struct ReadLimits {
  /// A chunk claiming more uncompressed bytes is malformed (rsg writes 1 MiB chunks).
  std::uint64_t max_chunk_bytes = 256ull << 20;
};

/// Visits every schema, channel and message of `file` (messages inside chunks too) in file order.
ScanResult scan(std::span<const std::uint8_t> file, RecordVisitor& visitor, const ReadLimits& limits = {});

/// A whole file in memory, read-only (mmap).
/// @throws rsg::InputError naming the file when it cannot be opened, rsg::EnvironmentError when
/// it cannot be mapped.
class MappedFile {
 public:
  explicit MappedFile(const std::filesystem::path& path);
  ~MappedFile();
  MappedFile(const MappedFile&) = delete;
  MappedFile& operator=(const MappedFile&) = delete;
  std::span<const std::uint8_t> bytes() const { return {data_, size_}; }

 private:
  const std::uint8_t* data_ = nullptr;
  std::size_t size_ = 0;
};

}  // namespace rsg::mcap
