// The MCAP records rsg writes and reads, as one table: each record type lists its fields in the
// order of the published MCAP specification (mcap.dev/spec), and that list alone drives both
// serialization (`append_record`) and parsing (`parse_record`). A field's C++ type says how the
// spec encodes it:
//
//   std::uint8_t/16/32/64        fixed width, little endian (Timestamp is a uint64 in ns)
//   std::string_view             String: uint32 byte length + UTF-8
//   Prefixed32 / Prefixed64      bytes with a uint32 / uint64 length prefix
//   Rest                         Bytes: everything up to the end of the record
//   std::vector<std::pair<K,V>>  Map<K,V> and Array<Tuple<K,V>>: uint32 byte length + pairs
//
// Parsed records are views into the bytes they were parsed from. No DDS, no file I/O here.
#pragma once

#include <cstdint>
#include <cstring>
#include <optional>
#include <span>
#include <string_view>
#include <tuple>
#include <utility>
#include <vector>

namespace rsg::mcap {

/// The file starts and ends with these 8 bytes; 0x30 is the major version ('0').
inline constexpr std::uint8_t kMagic[8] = {0x89, 'M', 'C', 'A', 'P', 0x30, '\r', '\n'};

enum class Opcode : std::uint8_t {
  header = 0x01,
  footer = 0x02,
  schema = 0x03,
  channel = 0x04,
  message = 0x05,
  chunk = 0x06,
  message_index = 0x07,
  chunk_index = 0x08,
  attachment = 0x09,
  attachment_index = 0x0A,
  statistics = 0x0B,
  metadata = 0x0C,
  metadata_index = 0x0D,
  summary_offset = 0x0E,
  data_end = 0x0F,
};

/// Every record starts with its opcode and a uint64 content length.
inline constexpr std::size_t kRecordPrefixBytes = 1 + 8;

struct Rest {
  std::span<const std::uint8_t> bytes;
};
struct Prefixed32 {
  std::span<const std::uint8_t> bytes;
};
struct Prefixed64 {
  std::span<const std::uint8_t> bytes;
};
using StringMap = std::vector<std::pair<std::string_view, std::string_view>>;
using ChannelOffsets = std::vector<std::pair<std::uint16_t, std::uint64_t>>;  // Map<uint16, uint64>
using TimeOffsets = std::vector<std::pair<std::uint64_t, std::uint64_t>>;  // Array<Tuple<Timestamp, uint64>>

struct Header {
  static constexpr Opcode opcode = Opcode::header;
  std::string_view profile{};
  std::string_view library{};
  static constexpr auto fields() { return std::tuple{&Header::profile, &Header::library}; }
};

struct Footer {
  static constexpr Opcode opcode = Opcode::footer;
  std::uint64_t summary_start = 0;
  std::uint64_t summary_offset_start = 0;
  std::uint32_t summary_crc = 0;
  static constexpr auto fields() {
    return std::tuple{&Footer::summary_start, &Footer::summary_offset_start, &Footer::summary_crc};
  }
};

struct Schema {
  static constexpr Opcode opcode = Opcode::schema;
  std::uint16_t id = 0;
  std::string_view name{};
  std::string_view encoding{};
  Prefixed32 data{};
  static constexpr auto fields() {
    return std::tuple{&Schema::id, &Schema::name, &Schema::encoding, &Schema::data};
  }
};

struct Channel {
  static constexpr Opcode opcode = Opcode::channel;
  std::uint16_t id = 0;
  std::uint16_t schema_id = 0;
  std::string_view topic{};
  std::string_view message_encoding{};
  StringMap metadata{};
  static constexpr auto fields() {
    return std::tuple{&Channel::id, &Channel::schema_id, &Channel::topic, &Channel::message_encoding,
                      &Channel::metadata};
  }
};

struct Message {
  static constexpr Opcode opcode = Opcode::message;
  std::uint16_t channel_id = 0;
  std::uint32_t sequence = 0;
  std::uint64_t log_time = 0;
  std::uint64_t publish_time = 0;
  Rest data{};
  static constexpr auto fields() {
    return std::tuple{&Message::channel_id, &Message::sequence, &Message::log_time, &Message::publish_time,
                      &Message::data};
  }
};

struct Chunk {
  static constexpr Opcode opcode = Opcode::chunk;
  std::uint64_t message_start_time = 0;
  std::uint64_t message_end_time = 0;
  std::uint64_t uncompressed_size = 0;
  std::uint32_t uncompressed_crc = 0;
  std::string_view compression{};
  Prefixed64 records{};
  static constexpr auto fields() {
    return std::tuple{&Chunk::message_start_time, &Chunk::message_end_time, &Chunk::uncompressed_size,
                      &Chunk::uncompressed_crc,   &Chunk::compression,      &Chunk::records};
  }
};

struct MessageIndex {
  static constexpr Opcode opcode = Opcode::message_index;
  std::uint16_t channel_id = 0;
  TimeOffsets records{};
  static constexpr auto fields() { return std::tuple{&MessageIndex::channel_id, &MessageIndex::records}; }
};

struct ChunkIndex {
  static constexpr Opcode opcode = Opcode::chunk_index;
  std::uint64_t message_start_time = 0;
  std::uint64_t message_end_time = 0;
  std::uint64_t chunk_start_offset = 0;
  std::uint64_t chunk_length = 0;  ///< the whole record, opcode and length included
  ChannelOffsets message_index_offsets{};
  std::uint64_t message_index_length = 0;
  std::string_view compression{};
  std::uint64_t compressed_size = 0;
  std::uint64_t uncompressed_size = 0;
  static constexpr auto fields() {
    return std::tuple{&ChunkIndex::message_start_time,    &ChunkIndex::message_end_time,
                      &ChunkIndex::chunk_start_offset,    &ChunkIndex::chunk_length,
                      &ChunkIndex::message_index_offsets, &ChunkIndex::message_index_length,
                      &ChunkIndex::compression,           &ChunkIndex::compressed_size,
                      &ChunkIndex::uncompressed_size};
  }
};

struct Statistics {
  static constexpr Opcode opcode = Opcode::statistics;
  std::uint64_t message_count = 0;
  std::uint16_t schema_count = 0;
  std::uint32_t channel_count = 0;
  std::uint32_t attachment_count = 0;
  std::uint32_t metadata_count = 0;
  std::uint32_t chunk_count = 0;
  std::uint64_t message_start_time = 0;
  std::uint64_t message_end_time = 0;
  ChannelOffsets channel_message_counts{};  ///< Map<uint16, uint64>: channel id -> messages
  static constexpr auto fields() {
    return std::tuple{
        &Statistics::message_count,      &Statistics::schema_count,     &Statistics::channel_count,
        &Statistics::attachment_count,   &Statistics::metadata_count,   &Statistics::chunk_count,
        &Statistics::message_start_time, &Statistics::message_end_time, &Statistics::channel_message_counts};
  }
};

struct SummaryOffset {
  static constexpr Opcode opcode = Opcode::summary_offset;
  std::uint8_t group_opcode = 0;
  std::uint64_t group_start = 0;
  std::uint64_t group_length = 0;
  static constexpr auto fields() {
    return std::tuple{&SummaryOffset::group_opcode, &SummaryOffset::group_start,
                      &SummaryOffset::group_length};
  }
};

struct DataEnd {
  static constexpr Opcode opcode = Opcode::data_end;
  std::uint32_t data_section_crc = 0;
  static constexpr auto fields() { return std::tuple{&DataEnd::data_section_crc}; }
};

namespace internal {

template <typename T>
constexpr bool kIsPairVector = false;
template <typename K, typename V>
constexpr bool kIsPairVector<std::vector<std::pair<K, V>>> = true;

template <typename T>
std::size_t field_size(const T& value) {
  if constexpr (std::is_integral_v<T>) {
    return sizeof(T);
  } else if constexpr (std::is_same_v<T, std::string_view>) {
    return 4 + value.size();
  } else if constexpr (std::is_same_v<T, Prefixed32>) {
    return 4 + value.bytes.size();
  } else if constexpr (std::is_same_v<T, Prefixed64>) {
    return 8 + value.bytes.size();
  } else if constexpr (std::is_same_v<T, Rest>) {
    return value.bytes.size();
  } else {
    static_assert(kIsPairVector<T>);
    std::size_t size = 4;
    for (const auto& [key, mapped] : value) size += field_size(key) + field_size(mapped);
    return size;
  }
}

template <typename Int>
void put_int(std::vector<std::uint8_t>& out, Int value) {
  for (std::size_t i = 0; i < sizeof(Int); ++i) out.push_back(static_cast<std::uint8_t>(value >> (8 * i)));
}

inline void put_bytes(std::vector<std::uint8_t>& out, std::span<const std::uint8_t> bytes) {
  out.insert(out.end(), bytes.begin(), bytes.end());
}

template <typename T>
void put_field(std::vector<std::uint8_t>& out, const T& value) {
  if constexpr (std::is_integral_v<T>) {
    put_int(out, value);
  } else if constexpr (std::is_same_v<T, std::string_view>) {
    put_int(out, static_cast<std::uint32_t>(value.size()));
    put_bytes(out, {reinterpret_cast<const std::uint8_t*>(value.data()), value.size()});
  } else if constexpr (std::is_same_v<T, Prefixed32>) {
    put_int(out, static_cast<std::uint32_t>(value.bytes.size()));
    put_bytes(out, value.bytes);
  } else if constexpr (std::is_same_v<T, Prefixed64>) {
    put_int(out, static_cast<std::uint64_t>(value.bytes.size()));
    put_bytes(out, value.bytes);
  } else if constexpr (std::is_same_v<T, Rest>) {
    put_bytes(out, value.bytes);
  } else {
    put_int(out, static_cast<std::uint32_t>(field_size(value) - 4));
    for (const auto& [key, mapped] : value) {
      put_field(out, key);
      put_field(out, mapped);
    }
  }
}

/// Reads fields front to back; every read is checked against what is left.
class Cursor {
 public:
  explicit Cursor(std::span<const std::uint8_t> bytes) : bytes_(bytes) {}
  std::size_t left() const { return bytes_.size(); }

  std::optional<std::span<const std::uint8_t>> take(std::uint64_t size) {
    if (size > bytes_.size()) return std::nullopt;
    const auto taken = bytes_.first(static_cast<std::size_t>(size));
    bytes_ = bytes_.subspan(static_cast<std::size_t>(size));
    return taken;
  }

  template <typename Int>
  bool get_int(Int& value) {
    const auto bytes = take(sizeof(Int));
    if (!bytes) return false;
    std::make_unsigned_t<Int> result = 0;
    for (std::size_t i = 0; i < sizeof(Int); ++i)
      result |= static_cast<std::make_unsigned_t<Int>>(static_cast<std::make_unsigned_t<Int>>((*bytes)[i])
                                                       << (8 * i));
    value = static_cast<Int>(result);
    return true;
  }

  template <typename T>
  bool get(T& value) {
    if constexpr (std::is_integral_v<T>) {
      return get_int(value);
    } else if constexpr (std::is_same_v<T, std::string_view>) {
      std::uint32_t size = 0;
      if (!get_int(size)) return false;
      const auto bytes = take(size);
      if (!bytes) return false;
      value = {reinterpret_cast<const char*>(bytes->data()), bytes->size()};
      return true;
    } else if constexpr (std::is_same_v<T, Prefixed32> || std::is_same_v<T, Prefixed64>) {
      std::conditional_t<std::is_same_v<T, Prefixed32>, std::uint32_t, std::uint64_t> size = 0;
      if (!get_int(size)) return false;
      const auto bytes = take(size);
      if (!bytes) return false;
      value.bytes = *bytes;
      return true;
    } else if constexpr (std::is_same_v<T, Rest>) {
      value.bytes = *take(bytes_.size());
      return true;
    } else {
      std::uint32_t size = 0;
      if (!get_int(size)) return false;
      const auto bytes = take(size);
      if (!bytes) return false;
      Cursor entries(*bytes);
      value.clear();
      while (entries.left() > 0) {
        typename T::value_type entry;
        if (!entries.get(entry.first) || !entries.get(entry.second)) return false;
        value.push_back(entry);
      }
      return true;
    }
  }

 private:
  std::span<const std::uint8_t> bytes_;
};

}  // namespace internal

/// The content length of `record` (without opcode and length prefix).
template <typename Record>
std::uint64_t content_size(const Record& record) {
  return std::apply(
      [&](auto... field) { return (std::uint64_t{0} + ... + internal::field_size(record.*field)); },
      Record::fields());
}

/// Appends opcode, length and content of `record` to `out`; returns the bytes appended.
template <typename Record>
std::uint64_t append_record(std::vector<std::uint8_t>& out, const Record& record) {
  const std::uint64_t size = content_size(record);
  out.push_back(static_cast<std::uint8_t>(Record::opcode));
  internal::put_int(out, size);
  std::apply([&](auto... field) { (internal::put_field(out, record.*field), ...); }, Record::fields());
  return kRecordPrefixBytes + size;
}

/// Parses a record's content (what follows opcode and length). Fails when a field runs past the end;
/// bytes after the last known field are ignored, as the spec says readers must (records may grow).
template <typename Record>
std::optional<Record> parse_record(std::span<const std::uint8_t> content) {
  Record record;
  internal::Cursor cursor(content);
  const bool complete =
      std::apply([&](auto... field) { return (cursor.get(record.*field) && ...); }, Record::fields());
  if (!complete) return std::nullopt;
  return record;
}

}  // namespace rsg::mcap
