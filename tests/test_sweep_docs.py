"""docs/sweep.md: the generated jump-speed tables match a fresh regeneration (benchmarks/sweep_docs.py)."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import pytest

from vtool.markdown import read_block

ROOT = Path(__file__).resolve().parent.parent


def _generator():  # type: ignore[no-untyped-def]
    spec = importlib.util.spec_from_file_location("sweep_docs", ROOT / "benchmarks" / "sweep_docs.py")
    module = importlib.util.module_from_spec(spec)  # type: ignore[arg-type]
    spec.loader.exec_module(module)  # type: ignore[union-attr]
    return module


@pytest.mark.slow
def test_committed_speed_tables_are_regenerated_unchanged() -> None:
    for name, text in _generator().deterministic_blocks().items():
        assert read_block(ROOT / "docs" / "sweep.md", name) == text, f"{name}: run python3 benchmarks/sweep_docs.py"
