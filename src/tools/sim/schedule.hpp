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

#include "rsg/wire/selection.hpp"

namespace rsg::tools::sim {

/// Bitwise union: the fields of both selections.
wire::Selection unite(const wire::Selection& a, const wire::Selection& b);

/// Parses a comma-separated list whose items are field names ("q") or group tokens ("g2"), or the
/// word "all". On failure returns false and names the offending item in `error`.
bool parse_selection_items(std::string_view list, wire::Selection& out, std::string& error);

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
  /// Adds an entry written "N:LIST" (N >= 1, LIST as parse_selection_items takes it).
  bool add(std::string_view spec, std::string& error);

  wire::Selection at(std::uint64_t frame) const;
  bool empty() const { return entries_.empty(); }
  const std::vector<Entry>& entries() const { return entries_; }

 private:
  std::vector<Entry> entries_;
};

}  // namespace rsg::tools::sim
