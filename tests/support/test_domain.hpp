// DDS domains for C++ tests that run side by side (ctest -j): the allocator of
// tests/support/test_domain.py (its docstring says why the pool is 20 to 99), keep the two in step.
// A test process holds its domain by an exclusive flock on <lock dir>/<domain>.lock until it exits.
#pragma once

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <stdexcept>
#include <string>

namespace rsg::test {

/// A domain no other running test holds; this process holds it until it exits.
/// @throws std::runtime_error when every domain of the pool is held
inline int acquire_domain() {
  constexpr int kFirstDomain = 20;
  constexpr int kLastDomain = 99;
  constexpr int kCount = kLastDomain - kFirstDomain + 1;
  const char* dir_env = std::getenv("RSG_TEST_LOCK_DIR");
  const std::filesystem::path dir = dir_env != nullptr ? dir_env : "/tmp/rsg-test-domains";
  std::filesystem::create_directories(dir);
  const int start = static_cast<int>(::getpid() % kCount);
  for (int step = 0; step < kCount; ++step) {
    const int domain = kFirstDomain + (start + step) % kCount;
    const std::string path = (dir / (std::to_string(domain) + ".lock")).string();
    const int fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0666);
    if (fd < 0) {
      throw std::runtime_error("cannot open " + path);
    }
    if (::flock(fd, LOCK_EX | LOCK_NB) == 0) {
      return domain;  // the descriptor stays open: the lock lasts as long as the process
    }
    ::close(fd);
  }
  throw std::runtime_error("all test DDS domains (20-99) are held by running tests: run fewer at once");
}

/// The DDS domain of this test process (acquired on the first call).
inline int test_domain() {
  static const int domain = acquire_domain();
  return domain;
}

}  // namespace rsg::test
