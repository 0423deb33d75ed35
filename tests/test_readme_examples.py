"""The example output in README.md is what `benchmarks/readme_examples.py` writes (wall times aside)."""

from __future__ import annotations

import importlib.util
import re
from pathlib import Path

from vtool.markdown import read_block

ROOT = Path(__file__).resolve().parent.parent


def without_times(text: str) -> str:
    text = re.sub(r" \(\+ [0-9.]+ s compiling or loading the solver\)", "", text)
    return re.sub(r"wall time [0-9.]+ s", "wall time", text)


def test_the_solve_example_regenerates() -> None:
    spec = importlib.util.spec_from_file_location("readme_examples", ROOT / "benchmarks" / "readme_examples.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)  # type: ignore[union-attr]
    assert without_times(read_block(ROOT / "README.md", "solve-1a")) == without_times(module.solve_1a())
