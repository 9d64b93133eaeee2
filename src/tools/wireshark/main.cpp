// rsg_wireshark_lua: writes the Wireshark dissector tools/wireshark/rsg_sendbuf.lua from its template
// and the field table, so that the dissector names, sizes and orders fields exactly as the codec does.
//
//   rsg_wireshark_lua TEMPLATE OUTPUT
//
// The template holds the dissector's logic; the line @RSG_GENERATED_TABLES@ becomes the tables.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <string_view>

#include "app/tool_main.hpp"
#include "rsg/wire/error.hpp"
#include "rsg/wire/error_flags.hpp"
#include "rsg/wire/field_docs.hpp"
#include "rsg/wire/field_table.hpp"
#include "rsg/wire/frame.hpp"

namespace {

// The gateway's port in the guides' examples and the Docker image (EXPOSE 17000/udp).
constexpr unsigned kDocumentedGatewayPort = 17000;
constexpr std::string_view kPlaceholder = "@RSG_GENERATED_TABLES@";

std::string_view type_name(rsg::wire::ElementType type) {
  switch (type) {
    case rsg::wire::ElementType::kFloat64:
      return "float64";
    case rsg::wire::ElementType::kErrorSet:
      return "error_set";
    case rsg::wire::ElementType::kUInt8:
      return "uint8";
    case rsg::wire::ElementType::kUInt64:
      return "uint64";
  }
  return "";
}

/// A Lua string literal; the table's texts are plain ASCII without quotes, but stay safe anyway.
std::string quoted(std::string_view text) {
  std::string out = "\"";
  for (char c : text) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + '"';
}

std::string tables() {
  std::ostringstream lua;
  lua << "-- Tables generated from include/rsg/wire/{field_table,field_docs,error_flags,error}.hpp.\n";
  lua << "local DEFAULT_PORT = " << kDocumentedGatewayPort << "\n";
  lua << "local REQUEST_TYPE = " << unsigned{rsg::wire::kRequestType} << "\n";
  lua << "local GROUP_COUNT = " << rsg::wire::kGroupCount << "\n";
  lua << "local MAX_ROBOT_MODE = " << unsigned{rsg::wire::kMaxRobotMode} << "\n";
  lua << "local ERROR_FLAG_COUNT = " << rsg::wire::kErrorFlagCount << "\n";
  lua << "local MAX_FRAME_BYTES = " << rsg::wire::kMaxFrameBytes << "\n";
  lua << "-- Validation categories in the order the spec checks them.\nlocal ERROR_CATEGORIES = {";
  for (std::size_t i = 1; i < rsg::wire::kErrorCategoryNames.size(); ++i)
    lua << (i == 1 ? " " : ", ") << quoted(rsg::wire::kErrorCategoryNames[i]);
  lua << " }\n";
  lua << "-- The field table in field-index order (the order of the data section).\nlocal FIELDS = {\n";
  for (const rsg::wire::FieldInfo& field : rsg::wire::kFields) {
    const rsg::wire::FieldDoc doc = rsg::wire::field_doc(field.id());
    char mask[8];
    std::snprintf(mask, sizeof mask, "0x%02x", unsigned{field.mask});
    lua << "  { name = " << quoted(field.name) << ", index = " << unsigned{field.index}
        << ", group = " << unsigned{field.group} << ", mask = " << mask
        << ", type = " << quoted(type_name(field.type)) << ", count = " << unsigned{field.count}
        << ", bytes = " << field.wire_bytes << ", rows = " << doc.matrix_rows
        << ", unit = " << quoted(doc.unit) << ", meaning = " << quoted(doc.meaning) << " },\n";
  }
  lua << "}\n-- Error-set bit -> flag name.\nlocal ERROR_FLAGS = {\n";
  for (std::size_t i = 0; i < rsg::wire::kErrorFlagNames.size(); ++i)
    lua << "  [" << i << "] = " << quoted(rsg::wire::kErrorFlagNames[i]) << ",\n";
  lua << "}\nlocal ROBOT_MODES = {";
  for (std::size_t i = 0; i < rsg::wire::kRobotModeNames.size(); ++i)
    lua << (i == 0 ? " " : ", ") << "[" << i << "] = " << quoted(rsg::wire::kRobotModeNames[i]);
  lua << " }";
  return lua.str();
}

}  // namespace

int main(int argc, char** argv) {
  rsg::app::init_logging("rsg_wireshark_lua");
  CLI::App app{"Writes the Wireshark dissector from its template and the field table.", "rsg_wireshark_lua"};
  std::string template_path;
  std::string output_path;
  app.add_option("TEMPLATE", template_path, "The dissector's template (rsg_sendbuf.lua.in)")->required();
  app.add_option("OUTPUT", output_path, "The dissector to write")->required();
  return rsg::app::run_main(app, argc, argv, [&] {
    std::ifstream in(template_path, std::ios::binary);
    if (!in) throw rsg::InputError("cannot read '" + template_path + "'");
    std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
    const std::size_t at = text.find(kPlaceholder);
    if (at == std::string::npos)
      throw rsg::InputError("'" + template_path + "' has no " + std::string(kPlaceholder));
    text.replace(at, kPlaceholder.size(), tables());
    std::ofstream out(output_path, std::ios::binary | std::ios::trunc);
    out << text;
    if (!out.flush()) throw rsg::EnvironmentError("cannot write '" + output_path + "'");
    return rsg::app::kExitOk;
  });
}
