// rsg_echo's human mode: stream statistics and a compact block of key values, redrawn in place.
#pragma once

#include <chrono>
#include <cstdint>
#include <string>

#include "rsg/wire/state_values.hpp"

namespace rsg::tools::echo {

using Clock = std::chrono::steady_clock;

/// What the table shows about the stream, fed one sample at a time.
class StreamStats {
 public:
  void add(const wire::StateValues& values, Clock::time_point now);

  std::uint64_t samples() const { return samples_; }
  /// Packet numbers skipped between consecutive samples (mod 16). On a view this includes the
  /// frames the view does not carry, and more than 15 frames lost in a row count as fewer.
  std::uint64_t packet_number_gaps() const { return gaps_; }
  /// Samples per second over the last complete second.
  double rate() const { return rate_; }
  const wire::StateValues& last() const { return last_; }
  Clock::time_point last_arrival() const { return last_arrival_; }

 private:
  std::uint64_t samples_ = 0;
  std::uint64_t gaps_ = 0;
  wire::StateValues last_;
  Clock::time_point last_arrival_;
  Clock::time_point window_start_;
  std::uint64_t window_samples_ = 0;
  double rate_ = 0;
};

/// Renders the table as lines of text; `header` is the first line (what is being read).
std::string render_table(const std::string& header, const StreamStats& stats, Clock::time_point now);

/// Draws successive tables over each other on a terminal: moves the cursor back over the lines
/// of the previous one and clears them. No curses: only the ANSI "cursor previous line" and
/// "erase below" sequences every terminal emulator understands.
class TerminalTable {
 public:
  void draw(const std::string& table);

 private:
  int previous_lines_ = 0;
};

}  // namespace rsg::tools::echo
