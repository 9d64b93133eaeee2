// The MCAP writer against rsg's own scanning reader: structure, crash cut-offs at every byte, and
// a write error in the middle of a recording. The reference reader (@mcap/core) checks the files
// rsg_record writes in record.mcap_reader (mcap_reader_test.mjs).
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <numeric>

#include "mcap/mcap_reader.hpp"
#include "mcap/mcap_recover.hpp"
#include "mcap/mcap_writer.hpp"

namespace rsg::mcap {
namespace {

namespace fs = std::filesystem;

struct Collected : RecordVisitor {
  std::vector<std::string> schemas, topics;
  std::vector<std::pair<std::uint16_t, std::vector<std::uint8_t>>> messages;
  std::vector<std::uint64_t> times;
  void on_schema(const Schema& schema) override { schemas.emplace_back(schema.name); }
  void on_channel(const Channel& channel) override { topics.emplace_back(channel.topic); }
  bool on_message(const Message& message) override {
    messages.emplace_back(message.channel_id,
                          std::vector<std::uint8_t>(message.data.bytes.begin(), message.data.bytes.end()));
    times.push_back(message.log_time);
    return true;
  }
};

std::vector<std::uint8_t> payload(std::uint32_t index) {
  std::vector<std::uint8_t> bytes(100 + index % 50);
  std::iota(bytes.begin(), bytes.end(), static_cast<std::uint8_t>(index));
  return bytes;
}

std::vector<std::uint8_t> read_file(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

class McapTest : public ::testing::Test {
 protected:
  fs::path path = fs::temp_directory_path() / ("rsg_mcap_test_" + std::to_string(::getpid()) + ".mcap");
  void TearDown() override { fs::remove(path); }

  /// 300 messages on two channels in chunks of about 4 KiB.
  void write_recording(Writer& writer, std::uint32_t count = 300) {
    const std::string idl = "module m { struct S { octet x; }; };";
    const auto schema =
        writer.add_schema("m::S", "omgidl", {reinterpret_cast<const std::uint8_t*>(idl.data()), idl.size()});
    const auto state = writer.add_channel(schema, "robot_state", "cdr", {});
    const auto status = writer.add_channel(schema, "status", "cdr", {{"k", "v"}});
    for (std::uint32_t i = 0; i < count; ++i)
      writer.write(i % 10 == 0 ? status : state, i, 1000 + i * 1000, 1000 + i * 1000, payload(i));
  }
  static WriterOptions small_chunks() { return {.chunk_bytes = 4096}; }
};

TEST_F(McapTest, ScannerReadsEveryMessageInOrder) {
  {
    Writer writer(path, small_chunks());
    write_recording(writer);
    writer.close();
    EXPECT_EQ(writer.totals().messages, 300u);
    EXPECT_GT(writer.totals().chunks, 5u);
  }
  const auto file = read_file(path);
  Collected seen;
  const ScanResult result = scan(file, seen);
  EXPECT_EQ(result.status, ScanResult::Status::complete) << result.error;
  ASSERT_EQ(seen.messages.size(), 300u);
  EXPECT_EQ(seen.schemas, std::vector<std::string>{"m::S"});
  EXPECT_EQ(seen.topics, (std::vector<std::string>{"robot_state", "status"}));
  for (std::uint32_t i = 0; i < 300; ++i) {
    EXPECT_EQ(seen.messages[i].first, i % 10 == 0 ? 2 : 1);
    EXPECT_EQ(seen.messages[i].second, payload(i));
  }
  EXPECT_TRUE(std::is_sorted(seen.times.begin(), seen.times.end()));
  // Ends with footer and magic; the footer points at the summary.
  ASSERT_GT(file.size(), 16u);
  EXPECT_TRUE(std::equal(std::begin(kMagic), std::end(kMagic), file.end() - 8));
}

TEST_F(McapTest, SyncFlushesEveryFinishedChunkAndTheEnd) {
  WriterOptions options = small_chunks();
  options.sync = true;
  Writer writer(path, options);
  write_recording(writer);
  writer.close();
  EXPECT_GT(writer.totals().chunks, 5u);
  EXPECT_EQ(writer.totals().syncs, writer.totals().chunks + 1);
  Writer unsynced(path, small_chunks());
  write_recording(unsynced);
  unsynced.close();
  EXPECT_EQ(unsynced.totals().syncs, 0u);
}

TEST_F(McapTest, SummaryHasStatisticsAndAChunkIndexPerChunk) {
  Writer writer(path, small_chunks());
  write_recording(writer);
  writer.close();
  const auto file = read_file(path);
  // Footer: opcode, length 20, summary_start, summary_offset_start, crc, then the magic.
  const std::size_t footer = file.size() - 8 - (1 + 8 + 20);
  ASSERT_EQ(file[footer], static_cast<std::uint8_t>(Opcode::footer));
  const auto parsed = parse_record<Footer>(std::span(file).subspan(footer + 9, 20));
  ASSERT_TRUE(parsed);
  std::size_t offset = parsed->summary_start;
  std::uint64_t chunk_indexes = 0;
  std::optional<Statistics> statistics;
  while (offset < parsed->summary_offset_start) {
    const auto opcode = static_cast<Opcode>(file[offset]);
    std::uint64_t length = 0;
    std::memcpy(&length, &file[offset + 1], 8);
    const auto content = std::span(file).subspan(offset + 9, length);
    if (opcode == Opcode::chunk_index) {
      const auto index = parse_record<ChunkIndex>(content);
      ASSERT_TRUE(index);
      EXPECT_EQ(file[index->chunk_start_offset], static_cast<std::uint8_t>(Opcode::chunk));
      EXPECT_EQ(index->compression, "zstd");
      ++chunk_indexes;
    } else if (opcode == Opcode::statistics) {
      statistics = parse_record<Statistics>(content);
    }
    offset += 9 + length;
  }
  EXPECT_EQ(chunk_indexes, writer.totals().chunks);
  ASSERT_TRUE(statistics);
  EXPECT_EQ(statistics->message_count, 300u);
  EXPECT_EQ(statistics->channel_count, 2u);
  EXPECT_EQ(statistics->chunk_count, chunk_indexes);
  EXPECT_EQ(statistics->channel_message_counts, (ChannelOffsets{{1, 270}, {2, 30}}));
}

// What a SIGKILL leaves: the file cut anywhere. Every cut reads as truncated, never malformed, and
// yields exactly the messages of the chunks that were whole before the cut.
TEST_F(McapTest, EveryCutOfTheFileReadsUpToItsLastWholeChunk) {
  // After each finished chunk: the file's size and the messages it holds.
  std::vector<std::pair<std::uint64_t, std::uint64_t>> chunk_ends;
  {
    Writer writer(path, small_chunks());
    const std::string idl = "module m { struct S { octet x; }; };";
    const auto schema =
        writer.add_schema("m::S", "omgidl", {reinterpret_cast<const std::uint8_t*>(idl.data()), idl.size()});
    const auto channel = writer.add_channel(schema, "t", "cdr", {});
    for (std::uint32_t i = 0; i < 120; ++i) {
      writer.write(channel, i, i, i, payload(i));
      if (writer.totals().chunks > chunk_ends.size())
        chunk_ends.emplace_back(writer.totals().file_bytes, writer.totals().messages);
    }
    writer.close();
  }
  const auto file = read_file(path);
  ASSERT_GE(chunk_ends.size(), 2u);
  // Where each chunk record ends (its message indexes follow it).
  std::vector<std::uint64_t> chunk_record_ends;
  for (std::size_t offset = 8; offset < chunk_ends.back().first;) {
    std::uint64_t length = 0;
    std::memcpy(&length, &file[offset + 1], 8);
    if (static_cast<Opcode>(file[offset]) == Opcode::chunk) chunk_record_ends.push_back(offset + 9 + length);
    offset += 9 + length;
  }
  ASSERT_EQ(chunk_record_ends.size(), chunk_ends.size());
  for (std::size_t cut = 0; cut < chunk_ends.back().first; ++cut) {
    Collected seen;
    const ScanResult result = scan(std::span(file).first(cut), seen);
    ASSERT_EQ(result.status, ScanResult::Status::truncated) << "cut at " << cut << ": " << result.error;
    std::uint64_t expected = 0;
    for (std::size_t chunk = 0; chunk < chunk_ends.size(); ++chunk)
      if (chunk_record_ends[chunk] <= cut) expected = chunk_ends[chunk].second;
    ASSERT_EQ(seen.messages.size(), expected) << "cut at " << cut;
    for (std::size_t i = 0; i < seen.messages.size(); ++i) ASSERT_EQ(seen.messages[i].second, payload(i));
  }
}

// rsg_record --recover: a file cut anywhere (what SIGKILL leaves) becomes a finished file, with the
// original header, holding exactly the messages a scan reads of the cut file.
TEST_F(McapTest, RecoverFinishesAFileCutAnywhere) {
  {
    Writer writer(path, {.profile = "ros2", .library = "test", .chunk_bytes = 4096});
    write_recording(writer);
    writer.close();
  }
  const auto file = read_file(path);
  const fs::path out = path.string() + ".recovered";
  for (std::size_t cut = 60; cut < file.size(); cut += 997) {
    Collected damaged;
    const ScanResult damaged_scan = scan(std::span(file).first(cut), damaged);
    const RecoverResult result = recover(std::span(file).first(cut), out, {.chunk_bytes = 8192});
    EXPECT_EQ(result.scan.status, damaged_scan.status) << "cut at " << cut;
    EXPECT_EQ(result.written.messages, damaged.messages.size()) << "cut at " << cut;
    const auto recovered = read_file(out);
    struct HeaderSeen : Collected {
      std::string profile, library;
      void on_header(const Header& header) override { profile = header.profile, library = header.library; }
    } header;
    ASSERT_EQ(scan(recovered, header).status, ScanResult::Status::complete) << "cut at " << cut;
    EXPECT_EQ(header.profile, "ros2");
    EXPECT_EQ(header.library, "test");
    EXPECT_EQ(header.messages, damaged.messages) << "cut at " << cut;
    EXPECT_EQ(header.topics, damaged.topics) << "cut at " << cut;
    // Finished: it ends with the magic after a footer.
    EXPECT_TRUE(std::equal(std::begin(kMagic), std::end(kMagic), recovered.end() - 8));
  }
  fs::remove(out);
}

// Disk full, simulated with a file size limit (the kernel refuses writes past it with EFBIG): the
// writer reports it and leaves a complete file with everything before the failed chunk.
TEST_F(McapTest, AWriteErrorLeavesAFinishedFileOfWhatCameBefore) {
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    std::signal(SIGXFSZ, SIG_IGN);
    const rlimit limit{20000, 20000};
    ::setrlimit(RLIMIT_FSIZE, &limit);
    try {
      Writer writer(path, small_chunks());
      write_recording(writer, 100000);
      writer.close();
      ::_exit(3);  // the limit should have stopped it
    } catch (const WriteError& error) {
      const std::string what = error.what();
      std::fprintf(stderr, "child: %s\n", what.c_str());
      ::_exit(what.find("File too large") != std::string::npos &&
                      what.find("the file was finished") != std::string::npos
                  ? 0
                  : 4);
    }
  }
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status));
  ASSERT_EQ(WEXITSTATUS(status), 0);
  const auto file = read_file(path);
  EXPECT_LE(file.size(), 20000u);
  Collected seen;
  const ScanResult result = scan(file, seen);
  EXPECT_EQ(result.status, ScanResult::Status::complete) << result.error;
  EXPECT_GT(seen.messages.size(), 50u);
  for (std::size_t i = 0; i < seen.messages.size(); ++i) ASSERT_EQ(seen.messages[i].second, payload(i));
  EXPECT_TRUE(std::equal(std::begin(kMagic), std::end(kMagic), file.end() - 8));
}

TEST_F(McapTest, AnUnwritablePathIsAClearError) {
  try {
    Writer writer("/nonexistent-dir/x.mcap", {});
    FAIL() << "no error";
  } catch (const WriteError& error) {
    EXPECT_STREQ(error.what(), "cannot create /nonexistent-dir/x.mcap: No such file or directory");
  }
}

TEST_F(McapTest, DamagedChunksAreMalformedNotCrashes) {
  {
    Writer writer(path, small_chunks());
    write_recording(writer, 50);
  }
  auto file = read_file(path);
  Collected intact;
  ASSERT_EQ(scan(file, intact).status, ScanResult::Status::complete);
  // Flip a byte inside the first chunk's compressed records: zstd or the CRC must notice.
  std::size_t offset = 8;
  while (static_cast<Opcode>(file[offset]) != Opcode::chunk) {
    std::uint64_t length = 0;
    std::memcpy(&length, &file[offset + 1], 8);
    offset += 9 + length;
  }
  file[offset + 200] ^= 0x40;
  Collected seen;
  const ScanResult result = scan(file, seen);
  EXPECT_EQ(result.status, ScanResult::Status::malformed);
  EXPECT_EQ(result.offset, offset);
  EXPECT_TRUE(seen.messages.empty());
  const std::vector<std::uint8_t> not_mcap{'h', 'e', 'l', 'l', 'o', ' ', 'w', 'o', 'r', 'l', 'd'};
  EXPECT_EQ(scan(not_mcap, seen).status, ScanResult::Status::malformed);
}

}  // namespace
}  // namespace rsg::mcap
