"""docs/trains.md: its generated tables and cam-shape figure are what benchmarks/trains_docs.py gives now."""

from __future__ import annotations

import importlib.util
from pathlib import Path

from vtool.markdown import read_block

ROOT = Path(__file__).resolve().parent.parent


def _generator():  # type: ignore[no-untyped-def]
    spec = importlib.util.spec_from_file_location("trains_docs", ROOT / "benchmarks" / "trains_docs.py")
    module = importlib.util.module_from_spec(spec)  # type: ignore[arg-type]
    spec.loader.exec_module(module)  # type: ignore[union-attr]
    return module


def test_committed_tables_and_figure_are_regenerated_unchanged() -> None:
    generator = _generator()
    for name, text in generator.blocks().items():
        assert read_block(ROOT / "docs" / "trains.md", name) == text, \
            f"{name}: run python benchmarks/trains_docs.py --write"
    assert generator.FIGURE.read_bytes() == generator.figure_bytes(), "run python benchmarks/trains_docs.py --write"
