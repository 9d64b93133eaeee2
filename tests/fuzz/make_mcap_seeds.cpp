// Writes seed MCAP files for fuzz_mcap_reader with rsg's own writer: zstd and uncompressed chunks,
// several channels, and a file cut inside its last chunk.
//
//   make_mcap_seeds OUT_DIR
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "mcap/mcap_writer.hpp"

namespace {

void write_seed(const std::filesystem::path& path, bool compress, std::uint32_t messages) {
  rsg::mcap::Writer writer(path,
                           {.profile = "ros2", .library = "seed", .chunk_bytes = 600, .compress = compress});
  const std::string idl = "module m { struct S { octet x; double y[2]; }; };";
  const auto schema =
      writer.add_schema("m::S", "omgidl", {reinterpret_cast<const std::uint8_t*>(idl.data()), idl.size()});
  const auto a = writer.add_channel(schema, "/a", "cdr", {{"offered_qos_profiles", "- history: 1"}});
  const auto b = writer.add_channel(schema, "b", "cdr", {});
  for (std::uint32_t i = 0; i < messages; ++i) {
    const std::vector<std::uint8_t> payload(20 + i % 7, static_cast<std::uint8_t>(i));
    writer.write(i % 3 == 0 ? b : a, i, 1000ull * i, 1000ull * i + 5, payload);
  }
  writer.close();
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) return 2;
  const std::filesystem::path dir = argv[1];
  std::filesystem::create_directories(dir);
  write_seed(dir / "zstd.mcap", true, 60);
  write_seed(dir / "plain.mcap", false, 40);
  write_seed(dir / "one.mcap", true, 1);
  // A killed recorder: the same file cut in the middle of its last chunk.
  const auto whole = std::filesystem::file_size(dir / "plain.mcap");
  std::filesystem::copy_file(dir / "plain.mcap", dir / "cut.mcap",
                             std::filesystem::copy_options::overwrite_existing);
  std::filesystem::resize_file(dir / "cut.mcap", whole * 2 / 3);
  return 0;
}
