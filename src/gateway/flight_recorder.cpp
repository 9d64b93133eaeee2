#include "gateway/flight_recorder.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <ctime>
#include <stdexcept>

#include "capture/pcap_file.hpp"
#include "gateway/errno_text.hpp"
#include "rsg/error.hpp"

namespace rsg::gateway {
namespace {

std::string utc_stamp(std::chrono::system_clock::time_point now) {
  const std::time_t seconds = std::chrono::system_clock::to_time_t(now);
  std::tm utc{};
  gmtime_r(&seconds, &utc);
  char text[32];
  std::strftime(text, sizeof text, "%Y%m%dT%H%M%S", &utc);
  const auto millis =
      std::chrono::duration_cast<std::chrono::milliseconds>(now.time_since_epoch()).count() % 1000;
  char with_millis[40];
  std::snprintf(with_millis, sizeof with_millis, "%s.%03dZ", text, static_cast<int>(millis));
  return with_millis;
}

}  // namespace

FlightRecorder::FlightRecorder(const Options& options, const transport::Endpoint& listen,
                               const transport::DatagramBatch& batch)
    : options_(options),
      listen_(capture::endpoint_of(listen.address())),
      slot_bytes_(batch.buffer_bytes()),
      kept_capacity_(static_cast<std::size_t>(std::ceil(options.window.count() * options.expected_rate * 2)) +
                     1) {
  slots_ = kept_capacity_ + batch.capacity();
  storage_.resize(slots_ * slot_bytes_);
  entries_.resize(slots_);
}

void FlightRecorder::lend(transport::DatagramBatch& batch) {
  for (std::size_t i = 0; i < batch.capacity(); ++i)
    batch.receive_into(i, {slot((next_ + i) % slots_), slot_bytes_});
}

void FlightRecorder::commit(const transport::DatagramBatch& batch, std::size_t received,
                            std::chrono::system_clock::time_point now, const SourceFilter& sources) {
  const auto time = std::chrono::duration_cast<std::chrono::nanoseconds>(now.time_since_epoch());
  std::size_t kept = 0;
  for (std::size_t i = 0; i < received; ++i) {
    const transport::DatagramBatch::Datagram datagram = batch[i];
    if (!options_.all_sources && !sources.allows(datagram.from.address())) {
      ++not_kept_;
      continue;
    }
    // Datagram i sits in the i-th lent slot; a skipped one before it leaves a gap to close. The
    // slot it moves to held a datagram already handled and not kept (or moved on itself).
    const std::size_t index = (next_ + kept) % slots_;
    if (kept != i) std::memcpy(slot(index), datagram.bytes.data(), datagram.bytes.size());
    Entry& entry = entries_[index];
    entry.time = time;
    entry.size = static_cast<std::uint32_t>(datagram.bytes.size());
    entry.from = capture::endpoint_of(datagram.from.address());
    ++kept;
  }
  next_ = (next_ + kept) % slots_;
  count_ = std::min(count_ + kept, kept_capacity_);
}

FlightRecorder::Snapshot FlightRecorder::snapshot(std::string_view reason) {
  const auto now = std::chrono::system_clock::now();
  Snapshot result;
  result.path = options_.dir / ("rsg_flight_" + utc_stamp(now) + "_" + std::to_string(++dumps_) + "_" +
                                std::string(reason) + ".pcap");
  result.to = listen_;
  if (count_ == 0) return result;
  const std::size_t oldest = (next_ + slots_ - count_) % slots_;
  const auto newest = entries_[(next_ + slots_ - 1) % slots_].time;
  const auto window = std::chrono::duration_cast<std::chrono::nanoseconds>(options_.window);
  std::size_t first = 0;  // entries are in arrival order: skip those older than the window
  while (first < count_ && newest - entries_[(oldest + first) % slots_].time > window) ++first;
  std::size_t total = 0;
  for (std::size_t i = first; i < count_; ++i) total += entries_[(oldest + i) % slots_].size;
  result.datagrams.reserve(count_ - first);
  result.bytes = std::make_unique_for_overwrite<std::uint8_t[]>(total);
  std::size_t offset = 0;
  for (std::size_t i = first; i < count_; ++i) {
    const std::size_t index = (oldest + i) % slots_;
    const Entry& entry = entries_[index];
    std::memcpy(result.bytes.get() + offset, slot(index), entry.size);
    result.datagrams.push_back({entry.time, entry.from, offset, entry.size});
    offset += entry.size;
  }
  return result;
}

FlightRecorder::Dump FlightRecorder::write(const Snapshot& snapshot) {
  Dump result{snapshot.path, 0};
  // A new file or none: whatever sits under the name (a file, a symlink planted to make the dump
  // overwrite something else) is left alone and the dump fails, named. Readable by the service's
  // group (an operator's), written by it alone.
  const int fd = ::open(snapshot.path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0640);
  if (fd < 0) {
    const int error = errno;
    throw EnvironmentError("cannot create '" + snapshot.path.string() + "': " + errno_text(error) +
                           (error == EEXIST ? ": something is there already, left alone" : ""));
  }
  std::FILE* file = ::fdopen(fd, "wb");
  if (file == nullptr) {
    const int error = errno;
    ::close(fd);
    throw EnvironmentError("cannot write '" + snapshot.path.string() + "': " + errno_text(error));
  }
  capture::PcapWriter writer(file, snapshot.path.string());
  for (const Snapshot::Datagram& datagram : snapshot.datagrams) {
    if (writer.write({datagram.time,
                      datagram.from,
                      snapshot.to,
                      {snapshot.bytes.get() + datagram.offset, datagram.size}}))
      ++result.frames;
  }
  writer.flush();
  return result;
}

// A pcap file: its 24-byte header, then per datagram a 16-byte record header and the IP packet
// (at most kMaxIpUdpHeader bytes of IPv6 and UDP headers in front of the payload).
std::uintmax_t FlightRecorder::file_bytes(const Snapshot& snapshot, std::size_t first) {
  std::uintmax_t total = 24;
  for (std::size_t i = first; i < snapshot.datagrams.size(); ++i)
    total += 16 + capture::kMaxIpUdpHeader + snapshot.datagrams[i].size;
  return total;
}

std::size_t FlightRecorder::keep_newest(Snapshot& snapshot, std::uintmax_t max_bytes) {
  std::uintmax_t total = file_bytes(snapshot);
  std::size_t first = 0;
  while (first < snapshot.datagrams.size() && total > max_bytes)
    total -= 16 + capture::kMaxIpUdpHeader + snapshot.datagrams[first++].size;
  snapshot.datagrams.erase(snapshot.datagrams.begin(),
                           snapshot.datagrams.begin() + static_cast<std::ptrdiff_t>(first));
  return first;
}

}  // namespace rsg::gateway
