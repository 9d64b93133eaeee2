// rsg_frame: converts SEND_BUF frames between binary, hex and the spec's canonical JSON, and writes
// selection requests. See `rsg_frame --help` and commands.hpp.
#include <CLI/CLI.hpp>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <iostream>
#include <string>

#include "app/tool_main.hpp"
#include "rsg/error.hpp"
#include "tools/frame/commands.hpp"

namespace {

using namespace rsg::tools::frame;

/// The input a subcommand reads: the named file, or standard input for "-".
class Input {
 public:
  /// @throws rsg::InputError when the file cannot be opened.
  explicit Input(const std::string& path) {
    if (path == "-") return;
    file_.open(path, std::ios::binary);
    if (!file_.is_open()) throw rsg::InputError("cannot open '" + path + "': " + std::strerror(errno));
    stream_ = &file_;
  }
  Input(const Input&) = delete;
  Input& operator=(const Input&) = delete;

  std::istream& stream() { return *stream_; }

 private:
  std::ifstream file_;
  std::istream* stream_ = &std::cin;
};

struct Options {
  std::string input = "-";
  bool hex_lines = false;
  unsigned packet_number = 0;
  rsg::wire::Selection selection;
};

void add_input(CLI::App& command, Options& options) {
  command.add_option("input", options.input, "File to read, - for standard input")->capture_default_str();
}

/// Adds `--groups` and `--fields`, exactly one of which fills `options.selection`. A list that does
/// not parse is a usage error, reported by CLI11 like any other.
void add_selection(CLI::App& command, Options& options) {
  auto* choice = command.add_option_group("selection", "What the robot should send (exactly one)");
  auto parse_into = [&options](auto parse, const char* option) {
    return [&options, parse, option](const std::string& list) {
      const rsg::wire::Parsed<rsg::wire::Selection> selection = parse(list);
      if (!selection) throw CLI::ValidationError(option, selection.error());
      options.selection = *selection;
    };
  };
  choice->add_option_function<std::string>("--groups", parse_into(rsg::wire::parse_group_list, "--groups"),
                                           "Comma-separated group numbers 0..5, every field of each");
  choice->add_option_function<std::string>("--fields", parse_into(rsg::wire::parse_field_list, "--fields"),
                                           "Comma-separated field names of docs/protocol.md, e.g. q,dq,time");
  choice->require_option(1);
}

}  // namespace

int main(int argc, char** argv) {
  std::ios::sync_with_stdio(false);
  rsg::app::init_logging("rsg_frame");

  CLI::App app{"Converts SEND_BUF frames (docs/protocol.md) between binary, hex and canonical JSON.",
               "rsg_frame"};
  app.require_subcommand(1);
  app.footer(
      "Exit status: 0 success (decode --hex-lines: the input was readable), 1 invalid frame, malformed "
      "JSON or hex, or an I/O error, 2 usage error or an input file that cannot be opened.");
  Options options;

  auto* decode = app.add_subcommand("decode", "Binary frame, or hex frames one per line -> canonical JSON");
  decode->add_flag("--hex-lines", options.hex_lines,
                   "One hex frame per line; each output line is canonical JSON or "
                   "{\"error\":CATEGORY,\"message\":...}, with \"selection_request\":{...} when the line "
                   "is a selection request (gateway -> robot) rather than a state frame");
  add_input(*decode, options);

  auto* encode = app.add_subcommand(
      "encode", "Canonical JSON, one object per line -> binary frames (stops at the first bad line)");
  encode->add_flag("--hex-lines", options.hex_lines, "Write one hex frame per line instead of binary");
  add_input(*encode, options);

  auto* request = app.add_subcommand("request", "Write a selection request (gateway -> robot)");
  add_selection(*request, options);
  request->add_option("--packet-number", options.packet_number, "Packet number 0..15")
      ->check(CLI::Range(0, 15))
      ->capture_default_str();
  request->add_flag("--hex,--hex-lines", options.hex_lines, "Write one hex line instead of binary");

  return rsg::app::run_main(app, argc, argv, [&] {
    const FrameFormat format = options.hex_lines ? FrameFormat::kHexLines : FrameFormat::kBinary;
    if (request->parsed())
      return write_selection_request({std::cin, std::cout, std::cerr},
                                     static_cast<std::uint8_t>(options.packet_number), options.selection,
                                     format);
    Input input(options.input);
    const Streams streams{input.stream(), std::cout, std::cerr};
    if (encode->parsed()) return encode_json_lines(streams, format);
    return options.hex_lines ? decode_hex_lines(streams) : decode_binary(streams);
  });
}
