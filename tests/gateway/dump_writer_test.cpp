// The flight recorder's bounds on the disk (DumpWriter): the minimum interval between dumps, and
// rsg's own files in the folder kept within a count and a byte cap, oldest deleted first; and what
// retention never deletes, and never follows (issue 51: docs/security.md's flight-recorder rows).
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
  DumpWriter writer({dir_, 0s, 3, 1 << 30, 10min});
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
  DumpWriter writer({dir_, 0s, 100, 1 << 20, 10min});
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

// A dump's name as FlightRecorder::snapshot makes it.
std::string dump_name(int n, const std::string& cause = "link_down") {
  return "rsg_flight_20261202T1500" + std::to_string(10 + n % 50) + ".000Z_" + std::to_string(n) + "_" +
         cause + ".pcap";
}

// Forged flaps at --pcap-max-files 5 --pcap-min-interval 1 (issue 51): the real incident's dump,
// 5 minutes old, and the ones the flaps made are all younger than the protected age: once the
// folder is full the next dumps are not written (counted no_room), none is deleted.
TEST_F(DumpWriterTest, ForgedFlapsCannotRotateOutADumpYoungerThanTheProtectedAge) {
  const fs::path incident = file(dump_name(1), 1000, 5min);
  DumpWriter writer({dir_, 0s, 5, 1 << 30});  // the default protected age: an hour
  EXPECT_EQ(DumpWriter::kKeepYoungerThan, 1h);
  for (int flap = 2; flap <= 9; ++flap) {
    ASSERT_EQ(writer.post("link_down", Clock::now(), [&] { return snapshot(dump_name(flap), 3); }),
              DumpWriter::Posted::kQueued);
    for (int i = 0;
         i < 500 && writer.written() + writer.no_room() + writer.failed() < std::uint64_t(flap - 1); ++i)
      std::this_thread::sleep_for(10ms);
  }
  EXPECT_EQ(writer.written(), 4U);  // 5 files in the folder
  EXPECT_EQ(writer.no_room(), 4U);  // the control: flaps 6..9 would each have rotated one out
  EXPECT_EQ(writer.deleted(), 0U);
  EXPECT_TRUE(fs::exists(incident));
}

// Past the protected age the burst's own files go first; the last dump before the burst (followed
// by an hour without one) and the newest of each cause stay.
TEST_F(DumpWriterTest, TheLastDumpBeforeABurstAndTheNewestOfEachCauseOutliveTheBurst) {
  const fs::path signal = file(dump_name(1, "signal"), 1000, 50h);  // the operator's SIGUSR1
  const fs::path incident = file(dump_name(2), 1000, 48h);          // then a quiet day
  std::vector<fs::path> burst;                                      // forged, a second apart
  for (int i = 0; i < 4; ++i) burst.push_back(file(dump_name(3 + i), 1000, 2h - i * 1s));
  DumpWriter writer({dir_, 0s, 5, 1 << 30});
  for (int n = 0; n < 2; ++n) {
    ASSERT_EQ(writer.post("link_down", Clock::now(), [&] { return snapshot(dump_name(10 + n), 3); }),
              DumpWriter::Posted::kQueued);
    wait_written(writer, std::uint64_t(n + 1));
  }
  EXPECT_TRUE(fs::exists(signal));
  EXPECT_TRUE(fs::exists(incident));
  EXPECT_FALSE(fs::exists(burst[0]));
  EXPECT_FALSE(fs::exists(burst[1]));
  EXPECT_FALSE(fs::exists(burst[2]));
  EXPECT_TRUE(fs::exists(burst[3]));  // now the last before a quiet spell itself
  EXPECT_EQ(writer.deleted(), 3U);
  EXPECT_EQ(writer.no_room(), 0U);
  // The control: without the quiet spell after it (the burst starting a second after it) the
  // incident is one of the burst, and goes first.
  for (const auto& entry : fs::directory_iterator(dir_)) fs::remove(entry.path());
  const fs::path close_incident = file(dump_name(2), 1000, 2h + 1s);
  for (int i = 0; i < 4; ++i) file(dump_name(3 + i), 1000, 2h - i * 1s);
  DumpWriter control({dir_, 0s, 5, 1 << 30});
  ASSERT_EQ(control.post("link_down", Clock::now(), [&] { return snapshot(dump_name(10), 3); }),
            DumpWriter::Posted::kQueued);
  wait_written(control, 1);
  EXPECT_FALSE(fs::exists(close_incident));
}

// 100 files named like rsg's and dated 2100, planted by another user (here: owned by nobody): not
// rsg's, so neither counted nor deleted, and the real dumps are not deleted to make room for them.
TEST_F(DumpWriterTest, FilesOfAnotherOwnerAreNeverCountedNorDeletedHoweverTheyAreNamedAndDated) {
  ASSERT_EQ(::geteuid(), 0U) << "planting another user's files needs root (chown): run as root";
  std::vector<fs::path> planted;
  for (int i = 0; i < 100; ++i) {
    const fs::path path =
        file("rsg_flight_21000101T000000.000Z_" + std::to_string(i) + "_link_down.pcap", 10, 0s);
    fs::last_write_time(path, fs::file_time_type::clock::now() + 24h * 365 * 74);
    ASSERT_EQ(::chown(path.c_str(), 65534, 65534), 0);
    planted.push_back(path);
  }
  DumpWriter writer({dir_, 0s, 3, 1 << 30, 0s});
  for (int n = 0; n < 4; ++n) {
    ASSERT_EQ(writer.post("link_down", Clock::now(), [&] { return snapshot(dump_name(n), 3); }),
              DumpWriter::Posted::kQueued);
    wait_written(writer, std::uint64_t(n + 1));
    std::this_thread::sleep_for(20ms);  // distinct file times
  }
  for (const auto& path : planted) EXPECT_TRUE(fs::exists(path)) << path;
  EXPECT_EQ(writer.deleted(), 1U);  // of 4 real dumps at --pcap-max-files 3, one: the oldest
  EXPECT_FALSE(fs::exists(dir_ / dump_name(0)));
  for (int n = 1; n < 4; ++n) EXPECT_TRUE(fs::exists(dir_ / dump_name(n))) << n;
  // The control: the same files as the gateway's own count toward --pcap-max-files (103 with the
  // three real dumps: one had to go).
  for (const auto& path : planted) ASSERT_EQ(::chown(path.c_str(), 0, 0), 0);
  DumpWriter own({dir_, 0s, 103, 1 << 30, 0s});
  ASSERT_EQ(own.post("link_down", Clock::now(), [&] { return snapshot(dump_name(4), 3); }),
            DumpWriter::Posted::kQueued);
  wait_written(own, 1);
  EXPECT_EQ(own.deleted(), 1U) << "103 files: one had to go";
}

// A symlink named like an old dump is not rsg's file: not deleted, and its target untouched.
TEST_F(DumpWriterTest, ASymlinkNamedLikeADumpIsNeverDeletedNorItsTargetTouched) {
  const fs::path outside = fs::path(dir_.string() + "_outside");
  fs::create_directories(outside);
  const fs::path target = outside / "robot1.yaml";
  std::ofstream(target) << "listen: 0.0.0.0:17000\n";
  fs::create_symlink(target, dir_ / dump_name(0));
  fs::last_write_time(target, fs::file_time_type::clock::now() - 48h);
  DumpWriter writer({dir_, 0s, 1, 1 << 30, 0s});
  ASSERT_EQ(writer.post("link_down", Clock::now(), [&] { return snapshot(dump_name(1), 3); }),
            DumpWriter::Posted::kQueued);
  wait_written(writer, 1);
  EXPECT_TRUE(fs::is_symlink(dir_ / dump_name(0)));
  EXPECT_EQ(fs::file_size(target), 22U);
  EXPECT_EQ(writer.deleted(), 0U);
  fs::remove_all(outside);
}

// 90 symlinks under the names the next dumps take, pointing at an operator's file: each dump fails
// (counted, named) and the file is never written through (issue 51: a YAML configuration was
// overwritten with a 158 KB pcap). The control: with the symlink gone the same dump is written.
TEST_F(DumpWriterTest, ADumpIsNeverWrittenThroughASymlinkUnderItsName) {
  const fs::path outside = fs::path(dir_.string() + "_outside");
  fs::create_directories(outside);
  const fs::path target = outside / "robot1.yaml";
  std::ofstream(target) << "listen: 0.0.0.0:17000\n";
  for (int n = 0; n < 90; ++n) fs::create_symlink(target, dir_ / dump_name(n));
  DumpWriter writer({dir_, 0s, 100, 1 << 30, 0s});
  for (int n = 0; n < 90; n += 30) {
    ASSERT_EQ(writer.post("link_down", Clock::now(), [&] { return snapshot(dump_name(n), 3); }),
              DumpWriter::Posted::kQueued);
    for (int i = 0; i < 500 && writer.failed() < std::uint64_t(n / 30 + 1); ++i)
      std::this_thread::sleep_for(10ms);
  }
  EXPECT_EQ(writer.failed(), 3U);
  EXPECT_EQ(writer.written(), 0U);
  EXPECT_EQ(fs::file_size(target), 22U) << "written through the symlink";
  fs::remove(dir_ / dump_name(0));
  ASSERT_EQ(writer.post("link_down", Clock::now(), [&] { return snapshot(dump_name(0), 3); }),
            DumpWriter::Posted::kQueued);
  for (int i = 0; i < 500 && writer.written() + writer.failed() < 4; ++i) std::this_thread::sleep_for(10ms);
  ASSERT_EQ(writer.written(), 1U);
  EXPECT_TRUE(fs::is_regular_file(fs::symlink_status(dir_ / dump_name(0))));
  EXPECT_EQ(fs::file_size(target), 22U);
  fs::remove_all(outside);
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
