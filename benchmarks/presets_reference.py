"""docs/presets.md, the preset reference, generated from the loaders' own reads (vtool.presets.reference).

Run: ``python benchmarks/presets_reference.py --write`` writes docs/presets.md;
``--check`` exits 1 (naming the first differing line) when the file is not
what the loaders give now. tests/test_presets_reference.py runs the check.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from vtool.files import write_atomic
from vtool.presets.reference import markdown

DOC = Path(__file__).resolve().parent.parent / "docs" / "presets.md"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    mode = parser.add_mutually_exclusive_group(required=True)
    mode.add_argument("--write", action="store_true", help="write docs/presets.md")
    mode.add_argument("--check", action="store_true", help="exit 1 if docs/presets.md is not current")
    args = parser.parse_args(argv)
    text = markdown()
    if args.write:
        write_atomic(DOC, text)
        print(f"wrote docs/presets.md ({len(text.splitlines())} lines)")
        return 0
    current = DOC.read_text(encoding="utf-8") if DOC.exists() else ""
    if current == text:
        print("docs/presets.md is current")
        return 0
    old, new = current.splitlines(), text.splitlines()
    line = next((i for i, (a, b) in enumerate(zip(old, new, strict=False)) if a != b), min(len(old), len(new)))
    print(f"docs/presets.md is not current from line {line + 1}: run benchmarks/presets_reference.py --write")
    return 1


if __name__ == "__main__":
    sys.exit(main())
