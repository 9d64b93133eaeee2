#include "tools/sim/simulator.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>

#include "rsg/wire/json.hpp"

namespace rsg::tools::sim {

Simulator::Simulator(SimConfig config)
    : config_(std::move(config)),
      model_(config_.seed),
      // A different stream from the motion's, so enabling faults does not change the motion.
      faults_(config_.faults, config_.seed ^ 0x9E3779B97F4A7C15ULL) {}

wire::Selection Simulator::next_selection() const {
  return requested_ ? *requested_ : config_.schedule.at(frame_);
}

void Simulator::produce_frame() {
  if (config_.restart_after != 0 && frame_ == config_.restart_after) {
    boot_frame_ = frame_;
    paused_since_boot_ = {};
    ++report_.restarts;
  }
  const std::uint64_t since_boot = frame_ - boot_frame_;
  const auto since_start =
      std::chrono::nanoseconds(std::llround(static_cast<double>(since_boot) * 1e9 / config_.rate_hz)) +
      paused_since_boot_;
  values_.packet_number = static_cast<std::uint8_t>(since_boot % wire::kPacketNumberModulo);
  values_.selection = next_selection();
  model_.fill(since_start, values_.selection, values_);
}

std::chrono::nanoseconds Simulator::step(DatagramSink& sink) {
  produce_frame();
  const Fault fault = faults_.next(frame_);
  ++frame_;

  if (fault == Fault::kDrop) {
    ++report_.dropped;
  } else if (fault == Fault::kCorrupt) {
    current_.category = faults_.next_category();
    current_.size = craft_invalid(current_.category, values_, faults_.random(), current_.bytes);
    emit(current_, sink);
  } else {
    const wire::EncodeResult encoded = encode(values_.packet_number, values_.selection, values_.storage(),
                                              wire::StateValues::layout(), current_.bytes);
    assert(encoded && "the model only produces encodable values");
    current_.size = encoded.size;
    current_.category = wire::ErrorCategory::kNone;
    if (fault == Fault::kReorder && !holding_) {
      std::swap(held_, current_);
      holding_ = true;
    } else {
      emit(current_, sink);
      if (fault == Fault::kDuplicate) {
        emit(current_, sink);
        ++report_.duplicated;
      }
      // Released only behind a valid frame, so that a receiver can tell by the packet numbers.
      if (holding_) {
        emit(held_, sink);
        ++report_.reordered;
        holding_ = false;
      }
    }
  }

  if (config_.pause_after != 0 && frame_ == config_.pause_after) {
    paused_since_boot_ += config_.pause;
    ++report_.pauses;
    return config_.pause;
  }
  return {};
}

void Simulator::stall() { ++report_.stalls; }

void Simulator::finish(DatagramSink& sink) {
  if (!holding_) return;
  emit(held_, sink);
  holding_ = false;
}

wire::SelectionRequestResult Simulator::handle_request(std::span<const std::uint8_t> datagram) {
  const wire::SelectionRequestResult request = wire::decode_selection_request(datagram);
  if (request) {
    requested_ = request.selection;
    ++report_.selection_requests;
  } else {
    ++report_.invalid_requests;
  }
  return request;
}

void Simulator::emit(const Datagram& datagram, DatagramSink& sink) {
  if (!sink.send(datagram.view())) {
    ++report_.send_failures;
    return;
  }
  ++report_.sent;
  const auto now = std::chrono::steady_clock::now();
  if (last_sent_)
    report_.longest_gap_us = std::max<std::uint64_t>(
        report_.longest_gap_us,
        static_cast<std::uint64_t>(
            std::chrono::duration_cast<std::chrono::microseconds>(now - *last_sent_).count()));
  last_sent_ = now;
  if (datagram.category != wire::ErrorCategory::kNone) {
    ++report_.invalid_count(datagram.category);
    return;
  }
  ++report_.valid;
  if (record_) record(datagram.view());
}

void Simulator::record(std::span<const std::uint8_t> frame) {
  // Decoding what was sent, rather than printing values_, records exactly what a receiver gets.
  const wire::DecodeResult decoded = wire::decode(frame);
  assert(decoded);
  recorded_.assign(decoded.frame());
  record_line_.clear();
  wire::append_canonical_json(recorded_, record_line_);
  record_line_ += '\n';
  record_->write(record_line_.data(), static_cast<std::streamsize>(record_line_.size()));
}

}  // namespace rsg::tools::sim
