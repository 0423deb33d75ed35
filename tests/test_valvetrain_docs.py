"""docs/valvetrain.md: the figures of its prose (the thesis' disagreements, the static start, the
Newmark and event-rule figures, the exact back end's conditioning) match a fresh regeneration
(benchmarks/valvetrain_docs.py), and the figures once typed there are gone (issue 37)."""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.benchmark_scripts import load
from vtool.markdown import read_block

ROOT = Path(__file__).resolve().parent.parent
DOC = ROOT / "docs" / "valvetrain.md"


def _generator():  # type: ignore[no-untyped-def]
    return load("valvetrain_docs")


@pytest.mark.parametrize("name", ["thesis-disagreements", "static-start", "newmark-figures", "exact-conditioning"])
def test_committed_valvetrain_figures_are_regenerated_unchanged(name: str) -> None:
    block = _generator().BLOCKS[name]()
    assert read_block(DOC, name) == block, f"{name}: run python3 benchmarks/valvetrain_docs.py --write"


def test_the_figures_once_typed_in_the_prose_are_gone() -> None:
    text = DOC.read_text(encoding="utf-8")
    for typed in ("ω_max Δt = 1.37", "5.8e-3 in/s", "1e-3 of a step", "states 1.6e-6 off", "1e6 to 1e10",
                  "1.1–1.7 on 1A", "up to ~60", "about two rows per degree"):
        assert typed not in text, typed
