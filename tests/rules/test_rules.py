#!/usr/bin/env python3
"""The rules of CONTRIBUTING.md that a reading of the text can check, checked:

- include: every #include "..." of tests/ and examples/ names its file by the one include root
  ("rsg/..." from include/, a path from src/, "tests/..." from the checkout; examples only the
  installed "rsg/..."), never by a bare name (src/ and include/rsg/ are layers.no_upward_edges').
- thread: no std::thread in src/ or include/ (the rule is std::jthread).
- thread-name: a file of src/ that holds or starts a std::jthread (or the .hpp/.cpp beside it of the
  same name) names that thread rsg-<role> with pthread_setname_np, within Linux's 15 characters,
  and no two threads share a name (top -H, perf and tests/integration/thread_freeze.py find them).
- private: "detail" and "internal" mean one thing each (CONTRIBUTING.md, "Layers"). A header of
  include/rsg/<layer>/detail/ (installed, not API) puts its names in rsg::<layer>::detail; no header
  of src/ (never installed) declares a detail namespace; a layer with an installed API (wire,
  transport, dds) keeps every header of src/<layer>/ in src/<layer>/internal/, names in
  rsg::<layer>::internal.
- python-path: no Python test puts tests/support, or the folder of another suite (integration, ros2,
  net), on sys.path itself: the shared helpers (tests/support) are imported by name, on the
  PYTHONPATH that tests/support/python.py sets for ctest and the runners outside it export.
- figure: no measured figure in a comment of src/ or include/: a number with a unit of time, a
  ratio or a throughput, written as measured ("~5 %") or next to words that say so ("measured",
  "took", "costs"). Figures go into docs/benchmarks/, and the comment points there.

Each failure names the file, the line and the rule. Run by ctest as rules.code (label unit); by hand:
tests/rules/test_rules.py [CHECKOUT]. Standard library only.
"""

import re
import sys
from pathlib import Path

SOURCE_SUFFIXES = {".hpp", ".cpp", ".h", ".cc", ".c", ".in"}
INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"', re.M)
# Headers the build writes into its mirror of src/ or tests/ without a template beside them.
GENERATED = {"gateway/ros2_type_hashes.hpp", "tests/ros2/ros2_layout.hpp"}
THREAD = re.compile(r"\bstd::thread\b")
JTHREAD = re.compile(r"\bstd::jthread\b")
THREAD_NAME = re.compile(r'pthread_setname_np\(\s*::pthread_self\(\)\s*,\s*"([^"]*)"\s*\)')
ROLE = re.compile(r"rsg-[a-z0-9]+(-[a-z0-9]+)*")
FIGURE = re.compile(r"(~\s?)?\b\d+(?:[.,]\d+)?\s?(?:ns|us|µs|ms|s|cycles|%|GB/s|MB/s)(?![\w/])")
NAMESPACE = re.compile(r"^namespace\s+([\w:]+)\s*\{", re.M)
# The layers whose include/rsg/<layer>/ is the API of a client library; the gateway's one installed
# header is the embedded gateway's facade, and the rest of src/gateway is its internals.
API_LAYERS = ("wire", "transport", "dds")
SYS_PATH_HELPERS = re.compile(r"sys\.path\.(?:insert|append)\(.*[\"'/](?:integration|support|ros2|net)[\"']")
# The suites that run outside ctest in containers and put tests/support on their path themselves
# (make test-image, make test-service), until their run.sh exports PYTHONPATH as the others do.
SYS_PATH_OWN = {"tests/image/test_image.py", "tests/service/test_service.py"}
MEASURED = re.compile(r"\b(measured|measures|took|costs?|costing)\b", re.I)


def sources(root, *folders):
    for folder in folders:
        for path in sorted((root / folder).rglob("*")):
            if path.is_file() and path.suffix in SOURCE_SUFFIXES and "node_modules" not in path.parts:
                yield path


def code_of(line):
    """The line without its // comment (string literals with // are rare enough to ignore here)."""
    return line.split("//", 1)[0]


def resolves(name, root, examples):
    if name.startswith("rsg/"):
        return (root / "include" / name).is_file()
    if examples:
        return False
    if name in GENERATED:
        return True
    if "/" not in name or name.startswith(("src/", "include/")):
        return False
    base = root if name.startswith("tests/") else root / "src"
    return (base / name).is_file() or (base / (name + ".in")).is_file()


def check_includes(root):
    for path in sources(root, "tests", "examples"):
        examples = path.relative_to(root).parts[0] == "examples"
        text = path.read_text(errors="replace")
        for match in INCLUDE.finditer(text):
            if not resolves(match.group(1), root, examples):
                line = text.count("\n", 0, match.start()) + 1
                want = "rsg/... only: an example uses the installed API" if examples else \
                    "a path from src/ (\"gateway/config.hpp\") or the checkout (\"tests/support/vectors.hpp\")"
                yield f"{path.relative_to(root)}:{line}: include: \"{match.group(1)}\": not {want}"


def check_threads(root):
    names = {}
    for path in sources(root, "src", "include"):
        lines = path.read_text(errors="replace").split("\n")
        for number, line in enumerate(lines, 1):
            if THREAD.search(code_of(line)):
                yield f"{path.relative_to(root)}:{number}: thread: std::thread; the rule is std::jthread"
        for name in THREAD_NAME.findall("\n".join(lines)):
            names.setdefault(name, []).append(path.relative_to(root))
            if not ROLE.fullmatch(name) or len(name) > 15:
                yield f"{path.relative_to(root)}: thread-name: \"{name}\" is not rsg-<role> in 15 characters"
        if any(JTHREAD.search(code_of(line)) for line in lines):
            pair = [path.with_suffix(suffix) for suffix in (".hpp", ".cpp")]
            if not any(THREAD_NAME.search(p.read_text(errors="replace")) for p in {path, *pair} if p.is_file()):
                yield (f"{path.relative_to(root)}: thread-name: a std::jthread that does not name itself "
                       "rsg-<role> (pthread_setname_np(::pthread_self(), \"rsg-...\") here or beside it)")
    for name, paths in names.items():
        if len(paths) > 1:
            yield f"{paths[1]}: thread-name: \"{name}\" is taken already by {paths[0]}"


def check_private(root):
    for path in sorted((root / "include" / "rsg").glob("*/detail/*.hpp")):
        want = f"rsg::{path.parts[-3]}::detail"
        for name in NAMESPACE.findall(path.read_text(errors="replace")):
            if name != want:
                yield f"{path.relative_to(root)}: private: namespace {name} in detail/: installed but not API is {want}"
    for path in sources(root, "src"):
        if path.suffix != ".hpp":
            continue
        relative = path.relative_to(root / "src")
        text = path.read_text(errors="replace")
        if any(name == "detail" or name.endswith("::detail") for name in NAMESPACE.findall(text)) or \
                re.search(r"^\s*namespace detail\b", text, re.M):
            yield (f"src/{relative}: private: a detail namespace in a header that is never installed: "
                   "detail is installed-not-API (include/rsg/<layer>/detail/); this is internal")
        layer = relative.parts[0]
        if layer in API_LAYERS:
            if relative.parts[1] != "internal":
                yield (f"src/{relative}: private: a header of {layer}, whose API is include/rsg/{layer}/, "
                       f"outside src/{layer}/internal/")
            for name in NAMESPACE.findall(text):
                if name != f"rsg::{layer}::internal":
                    yield f"src/{relative}: private: namespace {name}: the headers of src/{layer}/ are rsg::{layer}::internal"


def check_python_path(root):
    for path in sorted((root / "tests").rglob("*.py")):
        relative = path.relative_to(root).as_posix()
        if "node_modules" in path.parts or relative in SYS_PATH_OWN:
            continue
        for number, line in enumerate(path.read_text(errors="replace").split("\n"), 1):
            if SYS_PATH_HELPERS.search(line.split("#", 1)[0]):
                yield (f"{relative}:{number}: python-path: a sys.path insert of tests/support or another suite's folder; "
                       "import the helper by name (tests/support is on PYTHONPATH: tests/support/python.py)")


def check_figures(root):
    for path in sources(root, "src", "include"):
        for number, line in enumerate(path.read_text(errors="replace").split("\n"), 1):
            comment = line.split("//", 1)[1] if "//" in line else ""
            for figure in FIGURE.finditer(comment):
                if figure.group(1) or MEASURED.search(comment):
                    yield (f"{path.relative_to(root)}:{number}: figure: \"{figure.group(0).strip()}\" in a comment: "
                           "measured figures go into docs/benchmarks/, the comment points there")
                    break


def main():
    root = Path(sys.argv[1] if len(sys.argv) > 1 else Path(__file__).resolve().parents[2]).resolve()
    failures = [*check_includes(root), *check_threads(root), *check_private(root), *check_python_path(root),
                *check_figures(root)]
    print("".join(f"FAIL: {failure}\n" for failure in failures) +
          f"rules (include, thread, thread-name, private, python-path, figure) read over src/, include/, tests/, examples/: "
          f"{len(failures)} broken")
    return int(bool(failures))


if __name__ == "__main__":
    sys.exit(main())
