// The stats file (src/gateway/stats_file.hpp): what a reader of the file sees after the gateway's
// writes, on the calling thread and through the writer thread.
#include "gateway/stats_file.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <thread>

namespace rsg::gateway {
namespace {

namespace fs = std::filesystem;

status::GatewayStats published(std::uint64_t count) {
  status::GatewayStats stats;
  stats.ingress.published = count;
  return stats;
}

class StatsFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("rsg_stats_file_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // The published count in the file, or -1 while there is no file.
  long long published_in_file() const {
    std::ifstream in(path());
    if (!in) return -1;
    return nlohmann::json::parse(in).at("frames_published").get<long long>();
  }
  // Until the file says `count` (the writer thread runs on its own time), at most 10 s.
  bool eventually_published(long long count) const {
    for (int i = 0; i < 1000; ++i) {
      if (published_in_file() == count) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return false;
  }
  std::string path() const { return (dir_ / "stats.json").string(); }

  fs::path dir_;
};

TEST_F(StatsFileTest, WriteNowWritesBeforeItReturns) {
  StatsFile file(path());
  file.write_now(published(7));
  EXPECT_EQ(published_in_file(), 7);
  EXPECT_FALSE(fs::exists(path() + ".partial"));
}

TEST_F(StatsFileTest, PostedStatsReachTheFileAndTheLatestWins) {
  StatsFile file(path());
  for (std::uint64_t count = 1; count <= 100; ++count) file.post(published(count));
  EXPECT_TRUE(eventually_published(100));
}

TEST_F(StatsFileTest, OlderPostedStatsNeverReplaceAWriteNow) {
  StatsFile file(path());
  for (int round = 0; round < 200; ++round) {
    file.post(published(1));
    file.write_now(published(2));
    ASSERT_EQ(published_in_file(), 2) << "round " << round;
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(50));  // the writer thread had its chance
  EXPECT_EQ(published_in_file(), 2);
}

TEST_F(StatsFileTest, WhatIsPendingIsWrittenAtDestruction) {
  {
    StatsFile file(path());
    file.write_now(published(1));
    file.post(published(3));
  }
  EXPECT_EQ(published_in_file(), 3);
}

TEST_F(StatsFileTest, NoPathWritesNothing) {
  StatsFile file("");
  file.write_now(published(1));
  file.post(published(2));
  EXPECT_TRUE(fs::is_empty(dir_));
}

TEST_F(StatsFileTest, AnUnwritableDirectoryIsLoggedNotThrown) {
  const std::string missing = (dir_ / "gone" / "stats.json").string();
  StatsFile file(missing);
  EXPECT_NO_THROW(file.write_now(published(1)));
  EXPECT_NO_THROW(file.post(published(2)));
  EXPECT_FALSE(fs::exists(missing));
}

}  // namespace
}  // namespace rsg::gateway
