#include "tools/echo/live_table.hpp"

#include <algorithm>
#include <cstdarg>
#include <cstdio>

#include "rsg/wire/error_flags.hpp"

namespace rsg::tools::echo {
namespace {

constexpr auto kRateWindow = std::chrono::seconds(1);
constexpr unsigned kPacketNumberModulus = 16;

// printf-style append; GCC 12 has no std::format.
__attribute__((format(printf, 2, 3))) void append(std::string& out, const char* format, ...) {
  char buffer[256];
  va_list args;
  va_start(args, format);
  const int written = std::vsnprintf(buffer, sizeof buffer, format, args);
  va_end(args);
  if (written > 0)
    out.append(buffer, std::min<std::size_t>(static_cast<std::size_t>(written), sizeof buffer - 1));
}

// One labelled line per key value; "-" when the last sample did not carry the field.
void append_field_line(std::string& out, const wire::StateValues& values, wire::Field field) {
  append(out, "%-11s", std::string(wire::info(field).name).c_str());
  if (!values.selection.contains(field)) {
    out += "-\n";
    return;
  }
  switch (field) {
    case wire::Field::O_T_EE: {
      const auto pose = values.doubles(field);  // column-major 4x4: translation is column 3
      append(out, "x %+.5g  y %+.5g  z %+.5g m\n", pose[12], pose[13], pose[14]);
      return;
    }
    case wire::Field::robot_mode: {
      const auto mode = values.integer(field);
      append(out, "%s (%llu)\n",
             mode <= wire::kMaxRobotMode ? std::string(wire::kRobotModeNames[mode]).c_str() : "?",
             static_cast<unsigned long long>(mode));
      return;
    }
    case wire::Field::time:
      append(out, "%llu ms\n", static_cast<unsigned long long>(values.integer(field)));
      return;
    default:
      out += '[';
      for (const double element : values.doubles(field)) append(out, " %+.5g", element);
      out += " ]\n";
      return;
  }
}

}  // namespace

void StreamStats::add(const wire::StateValues& values, Clock::time_point now) {
  if (samples_ == 0) {
    window_start_ = now;
  } else {
    gaps_ += (values.packet_number - last_.packet_number + kPacketNumberModulus - 1) % kPacketNumberModulus;
  }
  ++samples_;
  ++window_samples_;
  if (now - window_start_ >= kRateWindow) {
    rate_ = static_cast<double>(window_samples_) / std::chrono::duration<double>(now - window_start_).count();
    window_start_ = now;
    window_samples_ = 0;
  }
  last_ = values;
  last_arrival_ = now;
}

std::string render_table(const std::string& header, const StreamStats& stats, Clock::time_point now) {
  std::string out = header + '\n';
  if (stats.samples() == 0) {
    out += "waiting for samples\n";
    return out;
  }
  const wire::StateValues& last = stats.last();
  append(out, "samples %llu  rate %.1f/s  packet-number gaps %llu  last %.1f ms ago\n",
         static_cast<unsigned long long>(stats.samples()), stats.rate(),
         static_cast<unsigned long long>(stats.packet_number_gaps()),
         std::chrono::duration<double, std::milli>(now - stats.last_arrival()).count());
  append(out, "packet %u  group_select 0x%02x  data_select", last.packet_number, last.selection.group_select);
  for (const std::uint8_t byte : last.selection.data_select) append(out, " %02x", byte);
  out += '\n';
  for (const wire::Field field :
       {wire::Field::q, wire::Field::dq, wire::Field::O_T_EE, wire::Field::robot_mode, wire::Field::time})
    append_field_line(out, last, field);
  return out;
}

void TerminalTable::draw(const std::string& table) {
  std::string out;
  if (previous_lines_ > 0) append(out, "\x1b[%dF\x1b[J", previous_lines_);
  out += table;
  previous_lines_ = static_cast<int>(std::count(table.begin(), table.end(), '\n'));
  std::fwrite(out.data(), 1, out.size(), stdout);
  std::fflush(stdout);
}

}  // namespace rsg::tools::echo
