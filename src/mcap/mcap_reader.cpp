#include "mcap/mcap_reader.hpp"

#include <fcntl.h>
#include <isa-l/crc.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zstd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <memory>
#include <stdexcept>

#include "rsg/error.hpp"

namespace rsg::mcap {
namespace {

using Status = ScanResult::Status;

struct Record {
  Opcode opcode;
  std::span<const std::uint8_t> content;
};

/// Walks `<opcode><uint64 length><content>` records of one section (the file or a chunk).
class RecordCursor {
 public:
  explicit RecordCursor(std::span<const std::uint8_t> bytes) : bytes_(bytes) {}
  std::uint64_t offset() const { return offset_; }
  bool at_end() const { return offset_ == bytes_.size(); }

  /// The next whole record, or nothing when the bytes end inside one (offset() stays at its start).
  std::optional<Record> next() {
    const std::span<const std::uint8_t> left = bytes_.subspan(static_cast<std::size_t>(offset_));
    if (left.size() < kRecordPrefixBytes) return std::nullopt;
    std::uint64_t length = 0;
    internal::Cursor prefix(left.subspan(1, 8));
    prefix.get_int(length);
    if (length > left.size() - kRecordPrefixBytes) return std::nullopt;
    offset_ += kRecordPrefixBytes + length;
    return Record{static_cast<Opcode>(left[0]),
                  left.subspan(kRecordPrefixBytes, static_cast<std::size_t>(length))};
  }

 private:
  std::span<const std::uint8_t> bytes_;
  std::uint64_t offset_ = 0;
};

class Scanner {
 public:
  Scanner(RecordVisitor& visitor, const ReadLimits& limits) : visitor_(visitor), limits_(limits) {}

  ScanResult run(std::span<const std::uint8_t> file) {
    if (file.size() < sizeof kMagic || !std::equal(std::begin(kMagic), std::end(kMagic), file.begin()))
      return finish(file.size() < sizeof kMagic && std::equal(file.begin(), file.end(), std::begin(kMagic))
                        ? Status::truncated
                        : Status::malformed,
                    "not an MCAP file (no magic)", 0);
    RecordCursor cursor(file.subspan(sizeof kMagic));
    bool first = true;
    while (true) {
      const std::uint64_t offset = sizeof kMagic + cursor.offset();
      if (cursor.at_end())
        return finish(Status::truncated, "the file ends without a Data End record or footer", offset);
      const auto record = cursor.next();
      if (!record) return finish(Status::truncated, "the file ends inside a record", offset);
      if (first) {
        if (record->opcode != Opcode::header)
          return finish(Status::malformed, "the first record is not a header", offset);
        const auto header = parse_record<Header>(record->content);
        if (!header) return finish(Status::malformed, "the header record is too short", offset);
        visitor_.on_header(*header);
      }
      first = false;
      switch (record->opcode) {
        case Opcode::data_end:
        case Opcode::footer:
          return finish(Status::complete, "", offset);
        case Opcode::chunk:
          if (!chunk(record->content, offset)) return result_;
          break;
        default:
          if (!data_record(*record, offset)) return result_;
      }
    }
  }

 private:
  ScanResult finish(Status status, std::string error, std::uint64_t offset) {
    result_.status = status;
    result_.error = std::move(error);
    result_.offset = offset;
    return result_;
  }
  bool fail(std::string error, std::uint64_t offset) {
    finish(Status::malformed, std::move(error), offset);
    return false;
  }

  /// Schemas, channels and messages, inside a chunk or not; other records are skipped.
  bool data_record(const Record& record, std::uint64_t offset) {
    switch (record.opcode) {
      case Opcode::schema: {
        const auto schema = parse_record<Schema>(record.content);
        if (!schema) return fail("a schema record is too short", offset);
        visitor_.on_schema(*schema);
        return true;
      }
      case Opcode::channel: {
        const auto channel = parse_record<Channel>(record.content);
        if (!channel) return fail("a channel record is too short", offset);
        visitor_.on_channel(*channel);
        return true;
      }
      case Opcode::message: {
        const auto message = parse_record<Message>(record.content);
        if (!message) return fail("a message record is too short", offset);
        ++result_.messages;
        if (!visitor_.on_message(*message)) {
          finish(Status::stopped, "", offset);
          return false;
        }
        return true;
      }
      default:
        return true;
    }
  }

  bool chunk(std::span<const std::uint8_t> content, std::uint64_t offset) {
    const auto chunk = parse_record<Chunk>(content);
    if (!chunk) return fail("a chunk record is too short", offset);
    if (chunk->uncompressed_size > limits_.max_chunk_bytes)
      return fail(
          "a chunk claims " + std::to_string(chunk->uncompressed_size) + " bytes, more than the limit",
          offset);
    std::span<const std::uint8_t> records = chunk->records.bytes;
    if (chunk->compression == "zstd") {
      buffer_.resize(static_cast<std::size_t>(chunk->uncompressed_size));
      if (!context_) context_.reset(ZSTD_createDCtx());
      const std::size_t size =
          ZSTD_decompressDCtx(context_.get(), buffer_.data(), buffer_.size(), records.data(), records.size());
      if (ZSTD_isError(size))
        return fail(std::string("a chunk does not decompress: ") + ZSTD_getErrorName(size), offset);
      if (size != buffer_.size()) return fail("a chunk decompresses to another size than it claims", offset);
      records = buffer_;
    } else if (!chunk->compression.empty()) {
      return fail("a chunk uses compression '" + std::string(chunk->compression) + "', which rsg cannot read",
                  offset);
    } else if (records.size() != chunk->uncompressed_size) {
      return fail("an uncompressed chunk's size differs from what it claims", offset);
    }
    if (chunk->uncompressed_crc != 0 &&
        crc32_gzip_refl(0, records.data(), records.size()) != chunk->uncompressed_crc)
      return fail("a chunk's CRC does not match its records", offset);

    ++result_.chunks;
    RecordCursor cursor(records);
    while (!cursor.at_end()) {
      const auto record = cursor.next();
      if (!record) return fail("a record inside a chunk runs past the chunk's end", offset);
      if (!data_record(*record, offset)) return false;
    }
    return true;
  }

  struct FreeContext {
    void operator()(ZSTD_DCtx* context) const { ZSTD_freeDCtx(context); }
  };

  RecordVisitor& visitor_;
  const ReadLimits& limits_;
  ScanResult result_;
  std::vector<std::uint8_t> buffer_;
  std::unique_ptr<ZSTD_DCtx, FreeContext> context_;
};

}  // namespace

ScanResult scan(std::span<const std::uint8_t> file, RecordVisitor& visitor, const ReadLimits& limits) {
  return Scanner(visitor, limits).run(file);
}

MappedFile::MappedFile(const std::filesystem::path& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw InputError("cannot open " + path.string() + ": " + std::strerror(errno));
  struct stat status {};
  if (::fstat(fd, &status) != 0) {
    const int error = errno;
    ::close(fd);
    throw InputError("cannot stat " + path.string() + ": " + std::strerror(error));
  }
  // mmap of a directory fails with ENODEV ("No such device"), which names nothing the user did.
  if (!S_ISREG(status.st_mode)) {
    ::close(fd);
    throw InputError(path.string() +
                     (S_ISDIR(status.st_mode) ? " is a directory" : " is not a regular file") +
                     ", not an MCAP file");
  }
  size_ = static_cast<std::size_t>(status.st_size);
  if (size_ > 0) {
    void* data = ::mmap(nullptr, size_, PROT_READ, MAP_PRIVATE, fd, 0);
    const int error = errno;
    ::close(fd);
    if (data == MAP_FAILED)
      throw EnvironmentError("cannot map " + path.string() + ": " + std::strerror(error));
    data_ = static_cast<const std::uint8_t*>(data);
  } else {
    ::close(fd);
  }
}

MappedFile::~MappedFile() {
  if (data_ != nullptr) ::munmap(const_cast<std::uint8_t*>(data_), size_);
}

}  // namespace rsg::mcap
