"""RIHS01 type hashes (REP 2011) of the ROS 2 types rsg_gateway publishes, computed from .msg files
with Python's standard library alone, so that every build announces them, with or without a ROS 2
installation (cmake/rsg_ros2_type_hashes.cmake runs it at build time):

  type_hashes.py [--header OUT.hpp] [--print] --types pkg/msg/Type... -- MSG_ROOT...

Each MSG_ROOT is an interface package (a folder with msg/*.msg, named after the package:
ros2/rsg_msgs) or a folder of them (ros2/standard_msgs: the members of the standard types
the gateway uses, which ROS 2 fixes). --header writes the C++ header the gateway reads
(rsg::ros2_generated::kTypeHashes), --print writes "pkg/msg/Type RIHS01_..." lines.

REP 2011's hash, as rosidl_generator_type_description computes it: the type's description (its name
and its members' names and field types, in order) and the descriptions of every type it refers to,
directly or not (sorted by name), as one JSON object without the members' default values, dumped
with ", " and ": " as separators and ASCII only; RIHS01_ followed by the SHA-256 of that text in hex.
rosidl stays the judge: ros2.type_hashes_match_rosidl compares these hashes with rosidl's.
"""
import argparse
import hashlib
import json
import re
import sys
from pathlib import Path

# type_description_interfaces/msg/FieldType: the id of each element type (a .msg char is a uint8);
# an array adds 48, a bounded sequence 96, an unbounded sequence 144.
PRIMITIVE_TYPE_IDS = {
    "int8": 2, "uint8": 3, "char": 3, "int16": 4, "uint16": 5, "int32": 6, "uint32": 7, "int64": 8,
    "uint64": 9, "float32": 10, "float64": 11, "bool": 15, "byte": 16, "string": 17, "wstring": 18,
}
NESTED_TYPE_ID = 1
BOUNDED_STRING_TYPE_IDS = {"string": 21, "wstring": 22}
ARRAY, BOUNDED_SEQUENCE, UNBOUNDED_SEQUENCE = 48, 96, 144

FIELD = re.compile(r"(?P<type>[A-Za-z_][\w/]*(?:<=\d+)?)(?P<shape>\[(?:<=)?\d*\])?\s+(?P<name>[a-z][a-z0-9_]*)(?:\s+.*)?$")


class MsgError(Exception):
    pass


def field_type(text, shape, package, where):
    """The FieldType of a member spelled `text` (+ `shape`) in a .msg of `package`."""
    string_capacity, nested, capacity = 0, "", 0
    bounded = re.fullmatch(r"(w?string)<=(\d+)", text)
    if bounded:
        type_id, string_capacity = BOUNDED_STRING_TYPE_IDS[bounded.group(1)], int(bounded.group(2))
    elif text in PRIMITIVE_TYPE_IDS:
        type_id = PRIMITIVE_TYPE_IDS[text]
    else:
        parts = text.split("/")
        if len(parts) == 1:
            parts = [package, parts[0]]
        if len(parts) != 2 or not parts[1][:1].isupper():
            raise MsgError(f"{where}: unknown type {text}")
        type_id, nested = NESTED_TYPE_ID, f"{parts[0]}/msg/{parts[1]}"
    if shape == "[]":
        type_id += UNBOUNDED_SEQUENCE
    elif shape and shape.startswith("[<="):
        type_id, capacity = type_id + BOUNDED_SEQUENCE, int(shape[3:-1])
    elif shape:
        type_id, capacity = type_id + ARRAY, int(shape[1:-1])
    return {"type_id": type_id, "capacity": capacity, "string_capacity": string_capacity, "nested_type_name": nested}


def individual_description(path, package):
    """{type_name, fields} of one .msg file: its members; constants and comments are not part of it."""
    fields = []
    for number, line in enumerate(path.read_text().splitlines(), 1):
        code = line.split("#", 1)[0].strip()
        if not code:
            continue
        words = code.split(None, 1)
        if len(words) == 2 and re.match(r"[A-Z][A-Z0-9_]*\s*=", words[1]):
            continue  # a constant
        member = FIELD.match(code)
        if not member:
            raise MsgError(f"{path}:{number}: not a member: {line}")
        fields.append({"name": member["name"],
                       "type": field_type(member["type"], member["shape"], package, f"{path}:{number}")})
    if not fields:
        raise MsgError(f"{path}: no member (rosidl would add one; rsg publishes no such type)")
    return {"type_name": f"{package}/msg/{path.stem}", "fields": fields}


def load_descriptions(roots):
    """Every type of the interface packages under `roots`, by name."""
    descriptions = {}
    for root in map(Path, roots):
        packages = [root] if (root / "msg").is_dir() else sorted(p for p in root.iterdir() if (p / "msg").is_dir())
        if not packages:
            raise MsgError(f"{root}: no interface package (no msg/ folder)")
        for package in packages:
            for msg in sorted((package / "msg").glob("*.msg")):
                description = individual_description(msg, package.name)
                if description["type_name"] in descriptions:
                    raise MsgError(f"{msg}: {description['type_name']} is defined twice")
                descriptions[description["type_name"]] = description
    return descriptions


def full_description(type_name, descriptions):
    """The type's description and those of every type it refers to, directly or not, by name."""
    def lookup(name, referrer):
        if name not in descriptions:
            raise MsgError(f"{name} (used by {referrer}) is in none of the .msg folders")
        return descriptions[name]

    top = lookup(type_name, "--types")
    referenced = set()
    pending = [(field["type"]["nested_type_name"], type_name) for field in top["fields"]]
    while pending:
        name, referrer = pending.pop()
        if name and name not in referenced:
            referenced.add(name)
            pending += [(field["type"]["nested_type_name"], name) for field in lookup(name, referrer)["fields"]]
    return {"type_description": top,
            "referenced_type_descriptions": [descriptions[name] for name in sorted(referenced)]}


def type_hash(type_name, descriptions):
    text = json.dumps(full_description(type_name, descriptions), ensure_ascii=True, separators=(", ", ": "))
    return "RIHS01_" + hashlib.sha256(text.encode("utf-8")).hexdigest()


def header(hashes):
    lines = ["// Generated by ros2/type_hashes.py (REP 2011, from the .msg files) at build time: do not edit.",
             "#pragma once", "", "#include <array>", "#include <string_view>", "#include <utility>", "",
             "namespace rsg::ros2_generated {", "",
             "// ROS 2 type name (pkg/msg/Type) -> RIHS01 hash",
             f"inline constexpr std::array<std::pair<std::string_view, std::string_view>, {len(hashes)}> kTypeHashes{{{{"]
    lines += [f'    {{"{name}", "{value}"}},' for name, value in sorted(hashes.items())]
    lines += ["}};", "", "}  // namespace rsg::ros2_generated", ""]
    return "\n".join(lines)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--header", type=Path, help="write the C++ header here (only when it changes)")
    parser.add_argument("--print", action="store_true", help="print 'pkg/msg/Type RIHS01_...' lines")
    parser.add_argument("--types", nargs="+", required=True, help="the types to hash (pkg/msg/Type)")
    parser.add_argument("roots", nargs="+", help="interface packages, or folders of them")
    args = parser.parse_args()
    try:
        descriptions = load_descriptions(args.roots)
        hashes = {name: type_hash(name, descriptions) for name in args.types}
    except (MsgError, OSError) as error:
        print(f"type_hashes.py: {error}", file=sys.stderr)
        return 1
    if args.header:
        text = header(hashes)
        if not args.header.exists() or args.header.read_text() != text:
            args.header.write_text(text)
    if args.print:
        for name, value in sorted(hashes.items()):
            print(name, value)
    return 0


if __name__ == "__main__":
    sys.exit(main())
