#!/usr/bin/env python3
"""The layers of CONTRIBUTING.md, checked against the code: no #include and no CMake link runs from
a lower layer to a higher one, and gateway and tools, the two top layers, use neither each other.

    wire  ->  transport, capture, mcap, foxglove  ->  dds  ->  app, status  ->  gateway, tools

Each folder of src/ (and its include/rsg/<layer>/ headers) is a unit of the rank below; a unit may
use a unit of a lower rank, never one of its own rank or above (transport and the DDS-free leaves
stand side by side). The include graph is read from every #include "..." of src/ and include/rsg/,
each resolved by the one include root (a path from src/, or rsg/... from include/): a bare name, or
a name that is no header of the tree, fails. The link graph is read from every
target_link_libraries() of src/*/CMakeLists.txt, a target belonging to
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
    "status": 3,  # the gateway's counters and status sample, which rsg_view reads too
    "gateway": 4,
    "tools": 4,
}

# Headers the build generates without a template beside them in src/, by their path from src/ (the
# build writes them into the build tree's mirror of src/). fastddsgen's type support is not among
# them: it is a system header to rsg's code, included as <RobotState.h>.
GENERATED = {
    "gateway/ros2_type_hashes.hpp",  # cmake/rsg_ros2_type_hashes.cmake, from ros2/type_hashes.py
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


def resolve(name, root):
    """The file of src/ or include/ an #include "name" names, by the one rule (CONTRIBUTING.md,
    "One include root"), and its unit; or (None, why) when it names none. No search by file name:
    an include that only the including file's own folder would find fails."""
    if name.startswith("rsg/"):
        target = root / "include" / name
        if target.is_file():
            return unit_of(target, root), None
        return None, "no such header in include/"
    if "/" not in name:
        return None, "a bare name: write the header's path from src/"
    target = root / "src" / name
    if target.is_file() or target.with_name(target.name + ".in").is_file() or name in GENERATED:
        return unit_of(target, root), None
    return None, "no such header in src/ (nor one the build generates)"


def include_edges(root):
    """(from file, included name, from unit, to unit) for every #include "..." of src/ and
    include/rsg/, and the list of those that name no header by the rule."""
    files = [p for folder in ("src", "include/rsg") for p in (root / folder).rglob("*")
             if p.is_file() and p.suffix in SOURCE_SUFFIXES]
    edges = []
    unresolved = []
    for path in files:
        source_unit = unit_of(path, root)
        installed = path.relative_to(root).parts[0] == "include"
        for name in re.findall(r'^\s*#\s*include\s+"([^"]+)"', path.read_text(errors="replace"), re.M):
            target_unit, why = resolve(name, root)
            if why is None and installed and not name.startswith("rsg/"):
                why = "an installed header includes one that is not installed"
            if why is not None:
                unresolved.append(f"{path.relative_to(root)}: #include \"{name}\": {why}")
            elif target_unit is not None:
                edges.append((path.relative_to(root), name, source_unit, target_unit))
    return edges, unresolved


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

    includes, unresolved = include_edges(root)
    failures += unresolved
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
