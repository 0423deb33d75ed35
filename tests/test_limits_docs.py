"""docs/limits.md: the generated nominal runs, warnings, cost guard, run rules and extremes table match a fresh
regeneration (benchmarks/limits_docs.py; the extremes table's slow rows are written by --write only)."""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.benchmark_scripts import load
from vtool.markdown import read_block

ROOT = Path(__file__).resolve().parent.parent


def _generator():  # type: ignore[no-untyped-def]
    return load("limits_docs")


@pytest.mark.parametrize("name", ["limits-sane", "limits-nominal", "limits-default-damping", "limits-seat-warning",
                                  "limits-cost-text", "limits-cost-guard", "limits-step-limits",
                                  "limits-run-rules", "limits-extremes"])
def test_committed_limits_figures_are_regenerated_unchanged(name: str) -> None:
    block = _generator().BLOCKS[name]()
    assert read_block(ROOT / "docs" / "limits.md", name) == block, f"{name}: run python3 benchmarks/limits_docs.py"
    assert "0.0944 s" not in block and "163 events" not in block  # the stale figures it replaced
    assert "7,028" not in block and "5,871" not in block  # the extremes table's old-law rocker peaks
    assert "from 148 to 233" not in block and "1.4\nmillion" not in block  # typed figures these blocks replaced


def test_the_figures_once_typed_in_the_prose_are_gone() -> None:
    """The measured figures the page used to type in its prose (issue 37) are gone from it; each now
    stands in a generated block."""
    text = (ROOT / "docs" / "limits.md").read_text(encoding="utf-8")
    for typed in ("148 to 233", "1.4\nmillion", "9.4 × 10⁷", "1–2 million", "5.8e-3 in/s", "3.7 GB"):
        assert typed not in text, typed
