#include "tests/support/allocation_counter.hpp"

#include <dlfcn.h>
#include <execinfo.h>

#include <array>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <new>

namespace {

// Per thread, because operator new has no other place to find its counter.
struct ThreadCounts {
  bool counting = false;
  std::size_t by_fast_dds = 0;
  std::size_t by_rsg = 0;
  std::array<void*, 32> first_by_rsg{};
  int first_by_rsg_depth = 0;
};
thread_local ThreadCounts counts;

// The caller is the first frame outside this binary (operator new and everything inlined into
// the code under test live in it); when that is libfastrtps (2.x) or libfastdds (3.x), Fast DDS
// allocated.
bool called_from_fast_dds(void* const* frames, int depth) {
  Dl_info self{};
  ::dladdr(reinterpret_cast<void*>(&called_from_fast_dds), &self);
  for (int i = 0; i < depth; ++i) {
    Dl_info frame{};
    if (!::dladdr(frames[i], &frame)) return false;
    if (frame.dli_fbase == self.dli_fbase) continue;
    return frame.dli_fname &&
           (std::strstr(frame.dli_fname, "libfastrtps") || std::strstr(frame.dli_fname, "libfastdds"));
  }
  return false;
}

void count_allocation() {
  if (!counts.counting) return;
  counts.counting = false;  // backtrace() and dladdr() must not count themselves
  std::array<void*, 32> frames;
  const int depth = ::backtrace(frames.data(), static_cast<int>(frames.size()));
  if (called_from_fast_dds(frames.data(), depth)) {
    ++counts.by_fast_dds;
  } else if (counts.by_rsg++ == 0) {
    counts.first_by_rsg = frames;
    counts.first_by_rsg_depth = depth;
  }
  counts.counting = true;
}

void* allocate(std::size_t size, std::size_t alignment) {
  count_allocation();
  void* memory = alignment <= alignof(std::max_align_t)
                     ? std::malloc(size ? size : 1)
                     : std::aligned_alloc(alignment, (size + alignment - 1) / alignment * alignment);
  if (!memory) throw std::bad_alloc();
  return memory;
}

}  // namespace

void* operator new(std::size_t size) { return allocate(size, alignof(std::max_align_t)); }
void* operator new[](std::size_t size) { return allocate(size, alignof(std::max_align_t)); }
void* operator new(std::size_t size, std::align_val_t a) {
  return allocate(size, static_cast<std::size_t>(a));
}
void* operator new[](std::size_t size, std::align_val_t a) {
  return allocate(size, static_cast<std::size_t>(a));
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }

namespace rsg::test {

AllocationCounter::AllocationCounter() { counts = ThreadCounts{}; }
AllocationCounter::~AllocationCounter() { counts.counting = false; }
void AllocationCounter::resume() { counts.counting = true; }
void AllocationCounter::pause() { counts.counting = false; }
std::size_t AllocationCounter::by_fast_dds() const { return counts.by_fast_dds; }
std::size_t AllocationCounter::by_rsg() const { return counts.by_rsg; }

std::string AllocationCounter::first_by_rsg() const {
  if (counts.by_rsg == 0) return {};
  const std::unique_ptr<char*, decltype(&std::free)> symbols(
      ::backtrace_symbols(counts.first_by_rsg.data(), counts.first_by_rsg_depth), &std::free);
  std::string text;
  for (int i = 0; symbols && i < counts.first_by_rsg_depth; ++i)
    text.append(symbols.get()[i]).push_back('\n');
  return text;
}

}  // namespace rsg::test
