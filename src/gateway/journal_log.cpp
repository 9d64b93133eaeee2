#include "journal_log.hpp"

#include <spdlog/pattern_formatter.h>
#include <spdlog/sinks/base_sink.h>
#include <spdlog/spdlog.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <memory>
#include <mutex>
#include <string>

#include "rsg/wire/number.hpp"

namespace rsg::gateway {
namespace {

// stderr, each line behind "<N>". Formats with whatever pattern the logger gives its sinks.
class JournalSink : public spdlog::sinks::base_sink<std::mutex> {
 protected:
  void sink_it_(const spdlog::details::log_msg& message) override {
    spdlog::memory_buf_t line;
    formatter_->format(message, line);
    const std::string prefix = "<" + std::to_string(journal_priority(message.level)) + ">";
    std::fwrite(prefix.data(), 1, prefix.size(), stderr);
    std::fwrite(line.data(), 1, line.size(), stderr);
    std::fflush(stderr);
  }
  void flush_() override { std::fflush(stderr); }
};

}  // namespace

int journal_priority(spdlog::level::level_enum level) {
  switch (level) {
    case spdlog::level::critical:
      return 2;
    case spdlog::level::err:
      return 3;
    case spdlog::level::warn:
      return 4;
    case spdlog::level::info:
      return 6;
    default:
      return 7;
  }
}

bool stderr_is_journal() {
  const char* stream = std::getenv("JOURNAL_STREAM");
  if (stream == nullptr) return false;
  const std::string_view text(stream);
  const auto colon = text.find(':');
  if (colon == std::string_view::npos) return false;
  const auto device = wire::parse_number<std::uint64_t>(text.substr(0, colon));
  const auto inode = wire::parse_number<std::uint64_t>(text.substr(colon + 1));
  struct stat file {};
  if (!device || !inode || ::fstat(STDERR_FILENO, &file) != 0) return false;
  return file.st_dev == *device && file.st_ino == *inode;
}

void use_journal_priorities() {
  if (!stderr_is_journal()) return;
  const auto logger = spdlog::default_logger();
  auto sink = std::make_shared<JournalSink>();
  // The journal has the time, and the priority says what "warning:" said.
  sink->set_formatter(std::make_unique<spdlog::pattern_formatter>("%n: %v"));
  logger->sinks().clear();
  logger->sinks().push_back(std::move(sink));
}

}  // namespace rsg::gateway
