"""Every XML file rsg ships (xml_profiles/, the .xml.in templates included) is well-formed XML, as
a strict parser (Python's expat) reads it.

Why: Fast DDS reads profiles with TinyXML-2, which accepts what XML forbids, such as "--" inside a
comment; a gateway.xml with one (2026-11-29, "--egress-rate" in a comment) loaded in every test
while a conforming XML parser (expat, here) refuses the file.

    check_profiles_xml.py DIR
"""

import sys
import xml.parsers.expat
from pathlib import Path


def main():
    root = Path(sys.argv[1])
    files = sorted([*root.rglob("*.xml"), *root.rglob("*.xml.in")])
    if not files:
        print(f"no XML file under {root}: wrong directory?")
        return 1
    bad = []
    for path in files:
        parser = xml.parsers.expat.ParserCreate()
        try:
            parser.Parse(path.read_bytes(), True)
        except xml.parsers.expat.ExpatError as error:
            bad.append(f"{path}: {error}")
    for line in bad:
        print(line)
    print(f"{len(files)} XML files, {len(bad)} not well-formed")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
