// Counts heap allocations made on one thread and tells rsg's own from Fast DDS's.
//
//   rsg::test::AllocationCounter allocations;
//   allocations.resume();
//   publish_a_frame();
//   allocations.pause();
//   EXPECT_EQ(allocations.by_rsg(), 0U) << allocations.first_by_rsg();
//
// Linking rsg_test_allocation_counter replaces the program's global operator new, so a test that
// uses it is a binary of its own and stays out of the sanitizer build (sanitizers replace the
// allocator too). Only the counting thread counts: Fast DDS's own threads are not the hot path.
#pragma once

#include <cstddef>
#include <string>

namespace rsg::test {

class AllocationCounter {
 public:
  /// Starts from zero, paused.
  AllocationCounter();
  ~AllocationCounter();
  AllocationCounter(const AllocationCounter&) = delete;
  AllocationCounter& operator=(const AllocationCounter&) = delete;

  /// Counts the calling thread's allocations from now on.
  void resume();
  void pause();

  /// Allocations whose caller (the first frame outside this binary's operator new) is libfastrtps.
  std::size_t by_fast_dds() const;
  /// Every other allocation: rsg's code, or the standard library called from it.
  std::size_t by_rsg() const;
  std::size_t total() const { return by_fast_dds() + by_rsg(); }
  /// The backtrace of the first allocation counted against rsg, one frame a line; empty if none.
  std::string first_by_rsg() const;
};

}  // namespace rsg::test
