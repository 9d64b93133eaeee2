// rsg_shm_forge NAME: makes /dev/shm/NAME a well-formed Boost.Interprocess segment laid out as Fast
// DDS 2.9's data-sharing segments are (rbtree_best_fit, 32-bit offsets, iset_index) whose
// "notification_node" is 3 bytes, not Fast DDS's Notification: what a local process can leave in
// its own data-sharing reader's place for a writer to open (integration.shm_attacks). Exit 0 when
// made, 1 when not.
#include <boost/interprocess/managed_shared_memory.hpp>
#include <cstdint>
#include <exception>
#include <iostream>

namespace {

namespace bi = boost::interprocess;
using Segment = bi::basic_managed_shared_memory<
    char, bi::rbtree_best_fit<bi::mutex_family, bi::offset_ptr<void, std::uint32_t, std::uint64_t>>,
    bi::iset_index>;

struct NotANotification {
  char bytes[3];
};

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: rsg_shm_forge NAME\n";
    return 1;
  }
  try {
    bi::shared_memory_object::remove(argv[1]);
    Segment segment(bi::create_only, argv[1], 4096);
    segment.construct<NotANotification>("notification_node")();
  } catch (const std::exception& e) {
    std::cerr << "rsg_shm_forge: " << argv[1] << ": " << e.what() << '\n';
    return 1;
  }
  return 0;
}
