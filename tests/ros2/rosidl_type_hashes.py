"""The judge of ros2/type_hashes.py: the RIHS01 type hashes rosidl itself computes, printed as
"pkg/msg/Type RIHS01_..." lines. Run by ros2.type_hashes_match_rosidl with the Python of the
project's ROS 2 environment (make deps: .deps/ros2, ros2/env.sh sourced):

  rosidl_type_hashes.py WORK_DIR PACKAGE_DIR... [--standard pkg/msg/Type...]

- each PACKAGE_DIR (ros2/rsg_msgs) is an interface package: its msg/*.msg go through rosidl's own
  pipeline, rosidl_adapter (.msg -> .idl) then rosidl_generator_type_description (.idl -> type
  description with hashes);
- each --standard type's hash is read from the type description rosidl generated for it when its
  package was built (share/<pkg>/msg/<Type>.json on AMENT_PREFIX_PATH: the wheels' sensor_msgs and
  geometry_msgs, make deps' tf2_msgs).
"""
import argparse
import json
import os
import sys
from pathlib import Path

from rosidl_adapter.msg import convert_msg_to_idl
from rosidl_generator_type_description import generate_type_hash


def package_hashes(package_dir, work_dir):
    package_dir = package_dir.resolve()
    name = package_dir.name
    idl_dir = work_dir / "idl" / name / "msg"
    idl_dir.mkdir(parents=True, exist_ok=True)
    idl_tuples = []
    for msg in sorted((package_dir / "msg").glob("*.msg")):
        idl = convert_msg_to_idl(package_dir, name, msg.relative_to(package_dir), idl_dir)
        idl_tuples.append(f"{work_dir / 'idl' / name}:msg/{idl.name}")
    output_dir = work_dir / "type_description" / name
    arguments = work_dir / f"{name}_type_description_args.json"
    arguments.write_text(json.dumps({"package_name": name, "output_dir": str(output_dir), "idl_tuples": idl_tuples,
                                     "include_paths": []}))
    generate_type_hash(str(arguments))
    hashes = {}
    for description in sorted((output_dir / "msg").glob("*.json")):
        for entry in json.loads(description.read_text())["type_hashes"]:
            if entry["type_name"] == f"{name}/msg/{description.stem}":
                hashes[entry["type_name"]] = entry["hash_string"]
    return hashes


def standard_hash(type_name):
    package, kind, name = type_name.split("/")
    for prefix in os.environ.get("AMENT_PREFIX_PATH", "").split(":"):
        path = Path(prefix) / "share" / package / kind / f"{name}.json"
        if path.exists():
            for entry in json.loads(path.read_text())["type_hashes"]:
                if entry["type_name"] == type_name:
                    return entry["hash_string"]
    raise SystemExit(f"rosidl_type_hashes.py: no type description of {type_name} on AMENT_PREFIX_PATH (make deps)")


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("work_dir", type=Path)
    parser.add_argument("packages", type=Path, nargs="*")
    parser.add_argument("--standard", nargs="*", default=[])
    args = parser.parse_args()
    hashes = {}
    for package in args.packages:
        hashes.update(package_hashes(package, args.work_dir.resolve()))
    for type_name in args.standard:
        hashes[type_name] = standard_hash(type_name)
    for name, value in sorted(hashes.items()):
        print(name, value)
    return 0


if __name__ == "__main__":
    sys.exit(main())
