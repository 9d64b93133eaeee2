"""Checks the guides (README.md, docs/*.md) against the code.

    check_guides.py snippets --root SRC --cxx COMPILER --flags FILE   every ```cpp snippet compiles
    check_guides.py claims --root SRC                                 no stale claim is made again

snippets: each C++ snippet is compiled (-fsyntax-only) with the include directories and definitions
of a target that links the installed libraries (FILE, written by CMake). A snippet with a `main` is
compiled as it is; any other keeps its #include lines at file scope and becomes the body of a
function, so that a guide can show statements without the program around them. A snippet that needs
what the build does not have is named in NEEDS (with the word that shows it), never silently left out.

claims: sentences the code has made false once and that must not come back, e.g. that a view is
filtered on the writer's side (rsg's writers evaluate no reader's filter: docs/operating.md).
"""

import argparse
import re
import subprocess
import sys
import tempfile
from pathlib import Path

# Snippets that need a library this build does not have: (guide, a word the snippet must contain).
NEEDS = {("docs/ros2.md", "rclcpp::"): "rclcpp (a ROS 2 installation; make deps provides none)"}

# (pattern, why it is wrong) for claims a guide must not make. Case-insensitive, across line breaks.
STALE_CLAIMS = [
    (r"(?:view|content filter|filter)s?\b[^.]{0,80}?\b(?:on|at|by|in) the writer(?:'s|s')? side",
     "views are filtered by the reader, never by the gateway's writer (docs/operating.md)"),
    (r"writer[- ]side (?:content )?filter(?:ing|ed)? (?:of|for) (?:the |a )?views?",
     "views are filtered by the reader, never by the gateway's writer (docs/operating.md)"),
    # "writer-side filtering with the gateway's profile then holds on 3.1.2 as on 2.9" (issue 50).
    (r"writer[- ]side (?:content )?filter(?:ing|ed)?\b[^.]{0,80}?\bholds\b",
     "the gateway's writers filter nothing: views are filtered by the reader (docs/operating.md)"),
]
# Where a guide explains the writer-side filtering rsg turned off, or how to turn it on for one's own
# writer: a match within such a sentence is not a claim about rsg's views.
ALLOWED_CONTEXT = re.compile(r"until this version|fast dds'?s? \*?writer-side|register_group_filter|"
                             r"wants writer-side filtering|writersidefiltering", re.IGNORECASE)


def guides(root):
    return [root / "README.md", *sorted((root / "docs").glob("**/*.md"))]


def cpp_snippets(path):
    """(line number, code) of every ```cpp block."""
    lines = path.read_text().splitlines()
    snippets, start, body = [], None, []
    for number, line in enumerate(lines, 1):
        if start is None and re.match(r"^\s*```(?:cpp|c\+\+)\s*$", line):
            start, body = number, []
        elif start is not None and re.match(r"^\s*```\s*$", line):
            snippets.append((start, "\n".join(body)))
            start = None
        elif start is not None:
            body.append(line)
    return snippets


def translation_unit(code):
    if re.search(r"\bint\s+main\s*\(", code):
        return code
    includes = [line for line in code.splitlines() if line.lstrip().startswith("#include")]
    rest = [line for line in code.splitlines() if not line.lstrip().startswith("#include")]
    return "\n".join([*includes, "", "[[maybe_unused]] static void snippet() {", *rest, "}", ""])


def check_snippets(root, cxx, flags_file):
    # The compiler's own directories stay out: -I/usr/include ahead of them breaks libstdc++'s
    # #include_next <stdlib.h> (CMake leaves them out of a compile line itself).
    flags = list(dict.fromkeys(line.strip() for line in Path(flags_file).read_text().splitlines()
                               if line.strip() and line.strip() != "-I/usr/include"))
    failures, compiled = [], 0
    with tempfile.TemporaryDirectory(prefix="rsg_snippets_") as tmp:
        for guide in guides(root):
            relative = guide.relative_to(root).as_posix()
            for line, code in cpp_snippets(guide):
                needs = [why for (where, word), why in NEEDS.items() if where == relative and word in code]
                if needs:
                    print(f"{relative}:{line}: not compiled: needs {needs[0]}")
                    continue
                source = Path(tmp) / f"snippet_{compiled}.cpp"
                source.write_text(translation_unit(code))
                result = subprocess.run([cxx, "-std=c++20", "-fsyntax-only", *flags, str(source)],
                                        capture_output=True, text=True)
                compiled += 1
                if result.returncode != 0:
                    errors = [text for text in result.stderr.splitlines() if "error" in text][:5]
                    failures.append(f"{relative}:{line}: the snippet does not compile:\n  " + "\n  ".join(errors))
                else:
                    print(f"{relative}:{line}: compiles")
    # Every exception must still be needed: a snippet that lost its word leaves a stale entry.
    for (where, word), why in NEEDS.items():
        if not any(word in code for _, code in cpp_snippets(root / where)):
            failures.append(f"NEEDS names {where} ({word}), which has no such snippet any more")
    if compiled == 0:
        failures.append("no C++ snippet found: the extraction is broken")
    return failures


def check_claims(root):
    failures = []
    for guide in guides(root):
        text = guide.read_text()
        for pattern, why in STALE_CLAIMS:
            for match in re.finditer(pattern, text, re.IGNORECASE | re.DOTALL):
                sentence_start = max(text.rfind(".", 0, match.start()), text.rfind("\n\n", 0, match.start()))
                sentence_end = text.find(".", match.end())
                sentence = text[sentence_start + 1:sentence_end if sentence_end >= 0 else len(text)]
                if ALLOWED_CONTEXT.search(sentence):
                    continue
                line = text.count("\n", 0, match.start()) + 1
                failures.append(f"{guide.relative_to(root)}:{line}: '{' '.join(match.group(0).split())}': {why}")
    return failures


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("what", choices=["snippets", "claims"])
    parser.add_argument("--root", type=Path, required=True)
    parser.add_argument("--cxx")
    parser.add_argument("--flags")
    args = parser.parse_args()
    failures = check_snippets(args.root, args.cxx, args.flags) if args.what == "snippets" else check_claims(args.root)
    for failure in failures:
        print(f"FAIL: {failure}", file=sys.stderr)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
