#include "gateway/journal_log.hpp"

#include <fmt/format.h>
#include <spdlog/details/log_msg.h>
#include <spdlog/pattern_formatter.h>
#include <spdlog/sinks/base_sink.h>
#include <spdlog/spdlog.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <string>

#include "wire/internal/number.hpp"

namespace rsg::gateway {
namespace {

// A log line as one JSON object (json_log_line).
class JsonFormatter : public spdlog::formatter {
 public:
  explicit JsonFormatter(bool with_time) : with_time_(with_time) {}
  void format(const spdlog::details::log_msg& message, spdlog::memory_buf_t& dest) override {
    const std::string line = json_log_line(message, with_time_);
    dest.append(line.data(), line.data() + line.size());
    dest.push_back('\n');
  }
  std::unique_ptr<spdlog::formatter> clone() const override {
    return std::make_unique<JsonFormatter>(with_time_);
  }

 private:
  bool with_time_;
};

// stderr, each line behind "<N>", formatted without a time of its own: the journal has it. A
// pattern set on the logger later (rsg::app::log_with_timestamps) does not reach this sink.
class JournalSink : public spdlog::sinks::base_sink<std::mutex> {
 public:
  JournalSink() { use_text(); }
  void use_text() { own_formatter_ = std::make_unique<spdlog::pattern_formatter>("%n: %v"); }
  void use_json() { own_formatter_ = std::make_unique<JsonFormatter>(false); }

 protected:
  void sink_it_(const spdlog::details::log_msg& message) override {
    spdlog::memory_buf_t line;
    own_formatter_->format(message, line);
    const std::string prefix = "<" + std::to_string(journal_priority(message.level)) + ">";
    std::fwrite(prefix.data(), 1, prefix.size(), stderr);
    std::fwrite(line.data(), 1, line.size(), stderr);
    std::fflush(stderr);
  }
  void flush_() override { std::fflush(stderr); }
  void set_pattern_(const std::string&) override {}
  void set_formatter_(std::unique_ptr<spdlog::formatter>) override {}

 private:
  std::unique_ptr<spdlog::formatter> own_formatter_;  // guarded by the sink's mutex once logging
};

JournalSink* journal_sink() {
  for (const auto& sink : spdlog::default_logger()->sinks())
    if (auto* journal = dynamic_cast<JournalSink*>(sink.get())) return journal;
  return nullptr;
}

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
  const auto device = wire::internal::parse_number<std::uint64_t>(text.substr(0, colon));
  const auto inode = wire::internal::parse_number<std::uint64_t>(text.substr(colon + 1));
  struct stat file {};
  if (!device || !inode || ::fstat(STDERR_FILENO, &file) != 0) return false;
  return file.st_dev == *device && file.st_ino == *inode;
}

void use_journal_priorities() {
  if (!stderr_is_journal()) return;
  const auto logger = spdlog::default_logger();
  logger->sinks().clear();
  logger->sinks().push_back(std::make_shared<JournalSink>());
}

void use_json_log_lines() {
  if (JournalSink* journal = journal_sink())
    journal->use_json();
  else
    spdlog::default_logger()->set_formatter(std::make_unique<JsonFormatter>(true));
}

std::string json_log_line(const spdlog::details::log_msg& message, bool with_time) {
  nlohmann::ordered_json line;
  if (with_time) {
    const auto since_epoch = message.time.time_since_epoch();
    const std::time_t seconds = std::chrono::duration_cast<std::chrono::seconds>(since_epoch).count();
    const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(since_epoch).count() % 1000;
    std::tm utc{};
    ::gmtime_r(&seconds, &utc);
    line["time"] = fmt::format("{:04}-{:02}-{:02}T{:02}:{:02}:{:02}.{:03}Z", utc.tm_year + 1900,
                               utc.tm_mon + 1, utc.tm_mday, utc.tm_hour, utc.tm_min, utc.tm_sec, ms);
  }
  const auto level = spdlog::level::to_string_view(message.level);
  line["level"] = std::string(level.data(), level.size());
  line["logger"] = std::string(message.logger_name.data(), message.logger_name.size());
  line["message"] = std::string(message.payload.data(), message.payload.size());
  // Replacing what is not UTF-8 (a peer's bytes in a message) rather than throwing.
  return line.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

}  // namespace rsg::gateway
