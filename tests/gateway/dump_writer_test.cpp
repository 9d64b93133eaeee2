// The flight recorder's bounds on the disk (DumpWriter): the minimum interval between dumps, and
// rsg's own files in the folder kept within a count and a byte cap, oldest deleted first.
#include "gateway/dump_writer.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>

namespace rsg::gateway {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

class DumpWriterTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("rsg_dump_writer_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // A file of `bytes` bytes, last written `age` ago.
  fs::path file(const std::string& name, std::size_t bytes, std::chrono::seconds age) {
    const fs::path path = dir_ / name;
    std::ofstream(path, std::ios::binary) << std::string(bytes, 'x');
    fs::last_write_time(path, fs::file_time_type::clock::now() - age);
    return path;
  }

  FlightRecorder::Snapshot snapshot(const std::string& name, std::size_t datagrams = 0,
                                    std::uint32_t size = 100) {
    FlightRecorder::Snapshot result;
    result.path = dir_ / name;
    result.bytes = std::make_unique<std::uint8_t[]>(datagrams * size + 1);
    for (std::size_t i = 0; i < datagrams; ++i)
      result.datagrams.push_back({std::chrono::seconds(i), {}, i * size, size});
    return result;
  }

  static void wait_written(const DumpWriter& writer, std::uint64_t count) {
    for (int i = 0; i < 500 && writer.written() + writer.failed() < count; ++i)
      std::this_thread::sleep_for(10ms);
    ASSERT_EQ(writer.written(), count) << "failed: " << writer.failed();
  }

  fs::path dir_;
};

TEST_F(DumpWriterTest, ARequestSoonerThanTheMinimumIntervalIsCountedAndCostsNoCopy) {
  DumpWriter writer({dir_, 10s, 100, 1 << 30});
  const Clock::time_point start = Clock::now();
  int taken = 0;
  const auto take = [&] {
    ++taken;
    return snapshot("rsg_flight_" + std::to_string(taken) + ".pcap");
  };
  EXPECT_EQ(writer.post("first", start, take), DumpWriter::Posted::kQueued);
  EXPECT_EQ(writer.post("flap", start + 9s, take), DumpWriter::Posted::kThrottled);
  EXPECT_EQ(writer.post("signal", start + 9900ms, take), DumpWriter::Posted::kThrottled);
  EXPECT_EQ(taken, 1);
  EXPECT_EQ(writer.throttled(), 2U);
  EXPECT_EQ(writer.post("later", start + 10s, take), DumpWriter::Posted::kQueued);
  EXPECT_EQ(taken, 2);
  wait_written(writer, 2);
}

TEST_F(DumpWriterTest, TheOldestOfItsOwnFilesGoFirstToStayWithinTheFileCount) {
  std::vector<fs::path> old;
  for (int i = 0; i < 5; ++i)
    old.push_back(file("rsg_flight_old_" + std::to_string(i) + ".pcap", 1000, 1h - i * 1min));
  const fs::path foreign = file("capture.pcap", 1000, 2h);            // not rsg's name
  const fs::path lookalike = file("rsg_flight_notes.txt", 1000, 2h);  // not a dump's
  DumpWriter writer({dir_, 0s, 3, 1 << 30});
  ASSERT_EQ(writer.post("test", Clock::now(), [&] { return snapshot("rsg_flight_new.pcap", 3); }),
            DumpWriter::Posted::kQueued);
  wait_written(writer, 1);
  EXPECT_EQ(writer.deleted(), 3U);
  for (int i = 0; i < 5; ++i) EXPECT_EQ(fs::exists(old[i]), i >= 3) << old[i];
  EXPECT_TRUE(fs::exists(dir_ / "rsg_flight_new.pcap"));
  EXPECT_TRUE(fs::exists(foreign));
  EXPECT_TRUE(fs::exists(lookalike));
}

TEST_F(DumpWriterTest, TheOldestOfItsOwnFilesGoFirstToStayWithinTheByteCap) {
  std::vector<fs::path> old;
  for (int i = 0; i < 4; ++i)
    old.push_back(file("rsg_flight_old_" + std::to_string(i) + ".pcap", 400'000, 1h - i * 1min));
  DumpWriter writer({dir_, 0s, 100, 1 << 20});
  ASSERT_EQ(writer.post("test", Clock::now(), [&] { return snapshot("rsg_flight_new.pcap", 10); }),
            DumpWriter::Posted::kQueued);
  wait_written(writer, 1);
  EXPECT_EQ(writer.deleted(), 2U);
  EXPECT_FALSE(fs::exists(old[0]));
  EXPECT_FALSE(fs::exists(old[1]));
  EXPECT_TRUE(fs::exists(old[2]));
  std::uintmax_t total = 0;
  for (const auto& entry : fs::directory_iterator(dir_)) total += entry.file_size();
  EXPECT_LE(total, 1U << 20);
}

TEST(FlightRecorderSnapshot, ALargerDumpThanTheCapKeepsItsNewestDatagrams) {
  FlightRecorder::Snapshot snapshot;
  for (std::size_t i = 0; i < 10; ++i)
    snapshot.datagrams.push_back({std::chrono::seconds(i), {}, i * 100, 100});
  const std::uintmax_t per_datagram = (FlightRecorder::file_bytes(snapshot) - 24) / 10;
  EXPECT_EQ(FlightRecorder::keep_newest(snapshot, 24 + 3 * per_datagram), 7U);
  ASSERT_EQ(snapshot.datagrams.size(), 3U);
  EXPECT_EQ(snapshot.datagrams.front().time, std::chrono::seconds(7));
  EXPECT_EQ(FlightRecorder::keep_newest(snapshot, 1 << 20), 0U);
}

}  // namespace
}  // namespace rsg::gateway
