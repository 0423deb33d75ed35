"""docs/plate.md: the figures its prose quotes (exact-reference convergence, the window, the full
model's transient notes, the 24-DOF element, what an engineer should choose) match a fresh
regeneration (benchmarks/plate_docs.py), and the stale figures once typed there are gone (issue 37)."""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.benchmark_scripts import load
from vtool.markdown import read_block

ROOT = Path(__file__).resolve().parent.parent
DOC = ROOT / "docs" / "plate.md"
pytestmark = pytest.mark.xdist_group("plate_docs")  # one worker computes the studies once


@pytest.fixture(scope="module")
def generator():  # type: ignore[no-untyped-def]
    return load("plate_docs")


@pytest.mark.parametrize("name", ["plate-exact-convergence", "plate-window", "plate-a1-notes",
                                  "plate-velocity-note", "plate-table3-notes", "plate-choices"])
def test_committed_plate_figures_are_regenerated_unchanged(generator, name: str) -> None:  # type: ignore[no-untyped-def]
    assert read_block(DOC, name) == generator.BLOCKS[name](), f"{name}: run python3 benchmarks/plate_docs.py --write"


def test_the_stale_figures_once_typed_in_the_prose_are_gone() -> None:
    text = DOC.read_text(encoding="utf-8")
    for typed in ("takes 100 RK4 steps", "against 716 for A1", "whole peak gives 0.43 %", "would be 7 %",
                  "0.017 % low", "KS^2.3", "KS^1.5 h^-1.1", "5 to 354 rows", "about 1.5 %"):
        assert typed not in text, typed
