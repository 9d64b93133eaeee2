#include "rsg/wire/json.hpp"

#include <charconv>
#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>

#include "rsg/wire/error_flags.hpp"

namespace rsg::wire {
namespace {

void append_double(double value, std::string& out) {
  if (std::isnan(value)) {
    out += "\"nan\"";
  } else if (std::isinf(value)) {
    out += value > 0 ? "\"inf\"" : "\"-inf\"";
  } else if (value == 0.0 && std::signbit(value)) {
    out += "-0.0";  // "-0" would read back as the integer 0 and lose the sign
  } else {
    char buffer[32];
    const auto [end, ec] = std::to_chars(buffer, buffer + sizeof buffer, value);  // shortest round-trip
    out.append(buffer, end);
  }
}

void append_unsigned(std::uint64_t value, std::string& out) {
  char buffer[24];
  const auto [end, ec] = std::to_chars(buffer, buffer + sizeof buffer, value);
  out.append(buffer, end);
}

void append_field(const FieldInfo& field, const StateValues& values, std::string& out) {
  switch (field.type) {
    case ElementType::kFloat64: {
      const auto elements = values.doubles(field.id());
      if (field.is_scalar()) {
        append_double(elements[0], out);
        return;
      }
      out += '[';
      for (std::size_t i = 0; i < elements.size(); ++i) {
        if (i) out += ',';
        append_double(elements[i], out);
      }
      out += ']';
      return;
    }
    case ElementType::kErrorSet: {
      const std::uint64_t bits = values.integer(field.id());
      out += '[';
      bool first = true;
      for (std::size_t flag = 0; flag < kErrorFlagCount; ++flag) {
        if (!((bits >> flag) & 1U)) continue;
        if (!first) out += ',';
        first = false;
        out += '"';
        out += kErrorFlagNames[flag];
        out += '"';
      }
      out += ']';
      return;
    }
    case ElementType::kUInt8:
    case ElementType::kUInt64:
      append_unsigned(values.integer(field.id()), out);
      return;
  }
}

using Json = nlohmann::json;

/// What a step of the parser returns that reads into a StateValues it is given: done, or why not.
struct Read {};

bool read_unsigned(const Json& node, std::uint64_t max, std::uint64_t& out) {
  if (!node.is_number_unsigned() && !(node.is_number_integer() && node.get<std::int64_t>() >= 0))
    return false;
  out = node.get<std::uint64_t>();
  return out <= max;
}

bool read_double(const Json& node, double& out) {
  if (node.is_number()) {
    out = node.get<double>();
    return true;
  }
  if (!node.is_string()) return false;
  const auto& text = node.get_ref<const std::string&>();
  if (text == "nan")
    out = std::numeric_limits<double>::quiet_NaN();
  else if (text == "inf")
    out = std::numeric_limits<double>::infinity();
  else if (text == "-inf")
    out = -std::numeric_limits<double>::infinity();
  else
    return false;
  return true;
}

/// Reads `node` into `out`'s elements of `field`.
Parsed<Read> read_field(const FieldInfo& field, const Json& node, StateValues& out) {
  const std::string name(field.name);
  switch (field.type) {
    case ElementType::kFloat64: {
      auto elements = out.doubles(field.id());
      if (field.is_scalar()) {
        if (read_double(node, elements[0])) return Read{};
        return ParseFailure{name + ": expected a number or \"nan\"/\"inf\"/\"-inf\""};
      }
      if (!node.is_array() || node.size() != field.count)
        return ParseFailure{name + ": expected an array of " + std::to_string(field.count) + " numbers"};
      for (std::size_t i = 0; i < elements.size(); ++i) {
        if (!read_double(node[i], elements[i])) {
          return ParseFailure{name + "[" + std::to_string(i) +
                              "]: expected a number or \"nan\"/\"inf\"/\"-inf\""};
        }
      }
      return Read{};
    }
    case ElementType::kErrorSet: {
      if (!node.is_array()) return ParseFailure{name + ": expected an array of error flag names"};
      std::uint64_t bits = 0;
      for (const Json& flag : node) {
        const auto* text = flag.is_string() ? &flag.get_ref<const std::string&>() : nullptr;
        std::size_t bit = 0;
        while (text && bit < kErrorFlagCount && kErrorFlagNames[bit] != *text) ++bit;
        if (!text || bit == kErrorFlagCount)
          return ParseFailure{name + ": " + flag.dump() + " is not an error flag name"};
        bits |= std::uint64_t{1} << bit;
      }
      out.set_integer(field.id(), bits);
      return Read{};
    }
    case ElementType::kUInt8:
    case ElementType::kUInt64: {
      const std::uint64_t max =
          field.type == ElementType::kUInt8 ? 0xFF : std::numeric_limits<std::uint64_t>::max();
      std::uint64_t value = 0;
      if (!read_unsigned(node, max, value))
        return ParseFailure{name + ": expected an unsigned integer up to " + std::to_string(max)};
      out.set_integer(field.id(), value);
      return Read{};
    }
  }
  return ParseFailure{name + ": an element type this parser does not know"};
}

/// Reads packet_number, group_select and data_select into `out`.
Parsed<Read> read_header(const Json& root, StateValues& out) {
  std::uint64_t value = 0;
  if (!root.contains("packet_number") || !read_unsigned(root["packet_number"], 15, value))
    return ParseFailure{"packet_number: expected an integer 0..15"};
  out.packet_number = static_cast<std::uint8_t>(value);
  if (!root.contains("group_select") || !read_unsigned(root["group_select"], 255, value))
    return ParseFailure{"group_select: expected an integer 0..255"};
  out.selection.group_select = static_cast<std::uint8_t>(value);
  const Json* data_select = root.contains("data_select") ? &root["data_select"] : nullptr;
  if (!data_select || !data_select->is_array() || data_select->size() != kGroupCount)
    return ParseFailure{"data_select: expected an array of 6 integers 0..255"};
  for (std::size_t group = 0; group < kGroupCount; ++group) {
    if (!read_unsigned((*data_select)[group], 255, value))
      return ParseFailure{"data_select[" + std::to_string(group) + "]: expected an integer 0..255"};
    out.selection.data_select[group] = static_cast<std::uint8_t>(value);
  }
  return Read{};
}

}  // namespace

void append_canonical_json(const StateValues& values, std::string& out) {
  out += "{\"packet_number\":";
  append_unsigned(values.packet_number, out);
  out += ",\"group_select\":";
  append_unsigned(values.selection.group_select, out);
  out += ",\"data_select\":[";
  for (std::size_t group = 0; group < kGroupCount; ++group) {
    if (group) out += ',';
    append_unsigned(values.selection.data_select[group], out);
  }
  out += "],\"fields\":{";
  bool first = true;
  for (const FieldInfo& field : kFields) {
    if (!values.selection.contains(field.id())) continue;
    if (!first) out += ',';
    first = false;
    out += '"';
    out += field.name;
    out += "\":";
    append_field(field, values, out);
  }
  out += "}}";
}

std::string to_canonical_json(const StateValues& values) {
  std::string out;
  append_canonical_json(values, out);
  return out;
}

Parsed<StateValues> parse_canonical_json(std::string_view text) {
  Json root;
  try {
    root = Json::parse(text);
  } catch (const Json::exception& e) {  // parse_error, and out_of_range for numbers beyond double
    return ParseFailure{std::string("malformed JSON: ") + e.what()};
  }
  if (!root.is_object()) return ParseFailure{"expected a JSON object"};
  for (const auto& [key, value] : root.items()) {
    if (key != "packet_number" && key != "group_select" && key != "data_select" && key != "fields")
      return ParseFailure{"unknown key '" + key + "'"};
  }
  StateValues values;
  if (const auto header = read_header(root, values); !header) return ParseFailure{header.error()};
  if (!root.contains("fields") || !root["fields"].is_object())
    return ParseFailure{"fields: expected an object"};
  const Json& fields = root["fields"];
  for (const auto& [key, value] : fields.items()) {
    const auto field = find_field(key);
    if (!field) return ParseFailure{"fields: '" + key + "' is not a field name of docs/protocol.md"};
    if (!values.selection.contains(*field))
      return ParseFailure{"fields: '" + key + "' is not selected by data_select"};
    if (const auto read = read_field(info(*field), value, values); !read) return ParseFailure{read.error()};
  }
  for (const FieldInfo& field : kFields) {
    if (values.selection.contains(field.id()) && !fields.contains(field.name))
      return ParseFailure{"fields: '" + std::string(field.name) + "' is selected by data_select but missing"};
  }
  return values;
}

}  // namespace rsg::wire
