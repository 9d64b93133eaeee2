#!/usr/bin/env python3
"""The layers of CONTRIBUTING.md, checked against the code: no #include and no CMake link runs from
a lower layer to a higher one, and gateway and tools, the two top layers, use neither each other.

    wire  ->  transport, capture, mcap, foxglove  ->  dds  ->  app, gateway/status  ->  gateway, tools

Each folder of src/ (and its include/rsg/<layer>/ headers) is a unit of the rank below; a unit may
use a unit of a lower rank, never one of its own rank or above (transport and the DDS-free leaves
stand side by side). The include graph is read from every #include "..." of src/ and include/rsg/;
the link graph from every target_link_libraries() of src/*/CMakeLists.txt, a target belonging to
the folder that defines it. A folder or target the table does not know fails the test too, so a new
one must be placed here (and in CONTRIBUTING.md's table).

Run by ctest as layers.no_upward_edges; by hand: tests/layers/test_layers.py .
Standard library only.
"""

import os
import re
import sys
from pathlib import Path

# Rank of each unit: a unit may use only units of a lower rank.
RANKS = {
    "wire": 0,
    "transport": 1,
    "capture": 1,
    "mcap": 1,
    "foxglove": 1,
    "dds": 2,
    "app": 3,
    "gateway/status": 3,  # the gateway's counters and status sample, which rsg_view reads too
    "gateway": 4,
    "tools": 4,
}

# Generated headers (at build time, in the build tree) and the unit that generates them.
GENERATED = {
    "RobotState.h": "dds", "RobotStatePubSubTypes.h": "dds", "RobotStateTypeObject.h": "dds",
    "GatewayStatus.h": "dds", "GatewayStatusPubSubTypes.h": "dds", "GatewayStatusTypeObject.h": "dds",
    "StandardMessages.h": "gateway", "StandardMessagesPubSubTypes.h": "gateway",
    "ros2_type_hashes.hpp": "gateway",
    "recording_schemas.hpp": "app",
    "web_assets.hpp": "tools",
}

SOURCE_SUFFIXES = {".hpp", ".cpp", ".h", ".in"}


def unit_of(path, root):
    """The unit of a file of src/ or include/rsg/, or None."""
    parts = path.relative_to(root).parts
    if parts[0] == "src" and len(parts) > 3 and "/".join(parts[1:3]) in RANKS:
        return "/".join(parts[1:3])
    if parts[0] == "src" and len(parts) > 2:
        return parts[1]
    if parts[0] == "include" and len(parts) > 2 and parts[1] == "rsg":
        return "wire" if parts[2] == "error.hpp" else parts[2]
    return None


def include_edges(root):
    """(from file, included name, from unit, to unit) for every #include "..." that names a project file."""
    files = [p for folder in ("src", "include/rsg") for p in (root / folder).rglob("*")
             if p.is_file() and p.suffix in SOURCE_SUFFIXES]
    by_name = {}
    for path in files:
        by_name.setdefault(path.name, []).append(path)
    edges = []
    for path in files:
        source_unit = unit_of(path, root)
        for name in re.findall(r'^\s*#\s*include\s+"([^"]+)"', path.read_text(errors="replace"), re.M):
            if name.startswith("rsg/"):
                target = root / "include" / name
                target_unit = unit_of(target, root) if target.exists() else None
            elif Path(name).name in GENERATED:
                target_unit = GENERATED[Path(name).name]
            else:
                candidates = [path.parent / name] if (path.parent / name).exists() else \
                    by_name.get(Path(name).name, []) + by_name.get(Path(name).name + ".in", [])
                units = {unit_of(c, root) for c in candidates}
                target_unit = units.pop() if len(units) == 1 else None
            if target_unit is not None:
                edges.append((path.relative_to(root), name, source_unit, target_unit))
    return edges


def link_edges(root):
    """(CMakeLists.txt, target, library, from unit, to unit) for every project library a target links."""
    owner = {}
    texts = {}
    for cmake in (root / "src").rglob("CMakeLists.txt"):
        text = re.sub(r"#.*", "", cmake.read_text())
        texts[cmake] = text
        for target in re.findall(r"add_(?:library|executable)\(\s*([A-Za-z0-9_]+)", text):
            owner[target] = unit_of(cmake, root)
    edges = []
    for cmake, text in texts.items():
        for target, arguments in re.findall(r"target_link_libraries\(\s*([A-Za-z0-9_]+)([^)]*)\)", text):
            for library in re.findall(r"[A-Za-z0-9_:]+", arguments):
                if library in owner and target in owner:
                    edges.append((cmake.relative_to(root), target, library, owner[target], owner[library]))
    return edges, owner


def main():
    root = Path(sys.argv[1] if len(sys.argv) > 1 else ".").resolve()
    failures = []
    for folder in sorted((root / "src").iterdir()):
        if folder.is_dir() and folder.name not in RANKS:
            failures.append(f"src/{folder.name}: a folder the layer table does not know (add it to RANKS)")

    def upward(source, target):
        return source != target and (source not in RANKS or target not in RANKS or RANKS[target] >= RANKS[source])

    includes = include_edges(root)
    for path, name, source, target in includes:
        if upward(source, target):
            failures.append(f"{path}: #include \"{name}\": {source} uses {target}")
    links, owner = link_edges(root)
    for cmake, target, library, source, destination in links:
        if upward(source, destination):
            failures.append(f"{cmake}: {target} links {library}: {source} uses {destination}")
    for failure in failures:
        print(f"FAIL: {failure}")
    print(f"{len(includes)} includes and {len(links)} links between {len(owner)} targets read: "
          f"{len(failures)} against the layers")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
