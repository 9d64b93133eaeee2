// Loads the conformance vectors kept as delivered in tests/data/vectors, and rsg's own
// (oversized.jsonl: datagrams longer than any frame, docs/protocol.md step 1).
#pragma once

#include <fstream>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "rsg/wire/hex.hpp"

namespace rsg::test {

struct Vector {
  std::vector<std::uint8_t> frame;
  nlohmann::json expected;   ///< `decoded` for valid vectors, `error` for invalid ones
  std::string decoded_text;  ///< `decoded` re-serialised, for parse_canonical_json
};

inline std::vector<Vector> load_vectors(const std::string& file, const char* key) {
  std::ifstream in(std::string(RSG_TEST_DATA_DIR) + "/vectors/" + file);
  if (!in) throw std::runtime_error("cannot open vectors/" + file);
  std::vector<Vector> vectors;
  for (std::string line; std::getline(in, line);) {
    if (line.empty()) continue;
    const auto json = nlohmann::json::parse(line);
    Vector vector;
    wire::Parsed<std::vector<std::uint8_t>> frame = wire::from_hex(json.at("frame_hex").get<std::string>());
    if (!frame) throw std::runtime_error("frame_hex: " + frame.error());
    vector.frame = std::move(frame).value();
    vector.expected = json.at(key);
    vector.decoded_text = vector.expected.dump();
    vectors.push_back(std::move(vector));
  }
  return vectors;
}

inline std::vector<Vector> valid_vectors() { return load_vectors("valid.jsonl", "decoded"); }
inline std::vector<Vector> oversized_vectors() { return load_vectors("oversized.jsonl", "error"); }
/// The delivered invalid vectors, then rsg's oversized ones: every decoder must agree on all.
inline std::vector<Vector> invalid_vectors() {
  std::vector<Vector> vectors = load_vectors("invalid.jsonl", "error");
  for (Vector& vector : oversized_vectors()) vectors.push_back(std::move(vector));
  return vectors;
}

}  // namespace rsg::test
