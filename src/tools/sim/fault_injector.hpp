// Faults the simulator injects into its stream: lost, repeated, swapped and malformed datagrams.
#pragma once

#include <cstddef>
#include <cstdint>
#include <random>
#include <span>
#include <vector>

#include "rsg/wire/error.hpp"
#include "rsg/wire/frame.hpp"
#include "rsg/wire/state_values.hpp"

namespace rsg::tools::sim {

/// Every category of the spec's validation, in its order: what `--corrupt` cycles through by default.
std::vector<wire::ErrorCategory> all_error_categories();

struct FaultConfig {
  /// Probability per frame of each fault. A frame suffers at most one fault, so they sum to <= 1.
  double drop = 0;
  double duplicate = 0;
  double reorder = 0;
  double corrupt = 0;
  /// Deterministic variants, for tests: every Nth frame (frames N-1, 2N-1, ...) gets the fault; 0 never.
  std::uint64_t drop_every = 0;
  std::uint64_t duplicate_every = 0;
  std::uint64_t reorder_every = 0;
  std::uint64_t corrupt_every = 0;
  /// Categories that successive corrupted frames cycle through, so that each one gets its share.
  std::vector<wire::ErrorCategory> corrupt_categories = all_error_categories();
};

enum class Fault : std::uint8_t { kNone, kDrop, kCorrupt, kDuplicate, kReorder };

/// Decides, frame by frame, which fault to inject. Reproducible from the seed.
class FaultPlan {
 public:
  FaultPlan(FaultConfig config, std::uint64_t seed);

  /// The fault for frame `frame` (counted from 0). A deterministic rule beats a random draw; among
  /// rules that match the same frame, the order is drop, corrupt, duplicate, reorder.
  Fault next(std::uint64_t frame);
  /// The category the next corrupted frame gets.
  wire::ErrorCategory next_category();
  std::mt19937_64& random() { return random_; }

 private:
  FaultConfig config_;
  std::mt19937_64 random_;
  std::size_t next_category_ = 0;
};

/// Room a crafted datagram needs: a full frame plus the bytes `length_mismatch` may append.
inline constexpr std::size_t kCraftedDatagramBytes = wire::kMaxFrameBytes + 16;

/// Writes to `out` (at least kCraftedDatagramBytes) a datagram that a spec-conformant decoder rejects
/// with exactly `category`, made from the frame that `values` encodes to (its packet number and,
/// where the category allows, its selection); `random` picks among the ways to break it.
/// Returns the datagram's size. kNone gives the valid frame itself.
std::size_t craft_invalid(wire::ErrorCategory category, const wire::StateValues& values,
                          std::mt19937_64& random, std::span<std::uint8_t> out);

}  // namespace rsg::tools::sim
