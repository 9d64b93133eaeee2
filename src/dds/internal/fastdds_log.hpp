// Where Fast DDS's own log lines go: stderr, with everything else a program says, one write per
// line, and in colour only when stderr is a terminal. Fast DDS's StdoutErrConsumer colours every
// line (`ESC[37;1m...[SECURITY Error]`), which a journal, a file or a log shipper keeps as
// garbage around the text.
#pragma once

#include <unistd.h>

#include <fastdds/dds/log/Log.hpp>
#include <iostream>
#include <memory>
#include <sstream>

namespace rsg::dds::internal {

class StderrLogConsumer final : public eprosima::fastdds::dds::LogConsumer {
 public:
  /// `color`: whether to colour the lines (Fast DDS's terminal codes).
  explicit StderrLogConsumer(bool color) : color_(color) {}

  /// In colour when stderr is a terminal, else plain.
  static std::unique_ptr<StderrLogConsumer> for_stderr() {
    return std::make_unique<StderrLogConsumer>(::isatty(STDERR_FILENO) == 1);
  }

  void Consume(const eprosima::fastdds::dds::Log::Entry& entry) override {
    // Built whole, then written once: a line of Fast DDS's logging thread never interleaves with one
    // of the program's own.
    std::ostringstream line;
    print_timestamp(line, entry, color_);
    print_header(line, entry, color_);
    print_message(line, entry, color_);
    print_context(line, entry, color_);
    print_new_line(line, color_);
    std::cerr << line.str() << std::flush;
  }

 private:
  bool color_;
};

}  // namespace rsg::dds::internal
