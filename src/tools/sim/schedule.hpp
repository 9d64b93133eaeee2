// Which fields each frame carries: selections repeating at different periods.
//
//   rsg_sim --every 1:q,dq,time --every 100:g1
//
// sends q, dq and time in every frame and all of group 1 in frames 0, 100, 200, ... as well.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "rsg/wire/parsed.hpp"
#include "rsg/wire/selection.hpp"

namespace rsg::tools::sim {

/// Parses a comma-separated list whose items are field names ("q") or group tokens ("g2"), or the
/// word "all".
/// @return the union of the items, or a failure naming the offending item.
wire::Parsed<wire::Selection> parse_selection_items(std::string_view list);

/// A set of (period, selection) entries. Frame k carries the union of the selections whose period
/// divides k, so frame 0 carries every entry; a frame that no entry covers carries no field (a valid,
/// header-only frame).
class Schedule {
 public:
  struct Entry {
    std::uint64_t period = 1;
    wire::Selection selection;
  };

  Schedule() = default;
  /// The same selection in every frame.
  explicit Schedule(const wire::Selection& every_frame) { add(1, every_frame); }

  void add(std::uint64_t period, const wire::Selection& selection) {
    entries_.push_back({period, selection});
  }
  void add(const Entry& entry) { entries_.push_back(entry); }

  wire::Selection at(std::uint64_t frame) const;
  bool empty() const { return entries_.empty(); }
  const std::vector<Entry>& entries() const { return entries_; }

 private:
  std::vector<Entry> entries_;
};

/// Parses an entry written "N:LIST" (N >= 1, LIST as parse_selection_items takes it).
/// @return the entry, or a failure naming what is wrong with `spec`.
wire::Parsed<Schedule::Entry> parse_schedule_entry(std::string_view spec);

}  // namespace rsg::tools::sim
