"""docs/limits.md: the generated nominal runs, cost-guard line and extremes table match a fresh
regeneration (benchmarks/limits_docs.py; the extremes table's slow rows are written by --write only)."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import pytest

from vtool.markdown import read_block

ROOT = Path(__file__).resolve().parent.parent


def _generator():  # type: ignore[no-untyped-def]
    spec = importlib.util.spec_from_file_location("limits_docs", ROOT / "benchmarks" / "limits_docs.py")
    module = importlib.util.module_from_spec(spec)  # type: ignore[arg-type]
    spec.loader.exec_module(module)  # type: ignore[union-attr]
    return module


@pytest.mark.parametrize("name", ["limits-nominal", "limits-cost-guard", "limits-extremes"])
def test_committed_limits_figures_are_regenerated_unchanged(name: str) -> None:
    block = _generator().BLOCKS[name]()
    assert read_block(ROOT / "docs" / "limits.md", name) == block, f"{name}: run python3 benchmarks/limits_docs.py"
    assert "0.0944 s" not in block and "163 events" not in block  # the stale figures it replaced
    assert "7,028" not in block and "5,871" not in block  # the extremes table's old-law rocker peaks
