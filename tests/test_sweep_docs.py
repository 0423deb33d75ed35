"""docs/sweep.md: the generated jump-speed tables match a fresh regeneration (benchmarks/sweep_docs.py).

The whole regeneration takes a minute or more on the 2-core machine, three quarters of it in the
two train-type presets' rows (``direct-acting-bucket``, ``ohc-finger-follower``: their bounce-speed
searches run 56 points of up to 30 steady cycles each at a 0.5 µs step; 2026-11-27, 50 of 66 s). The
suite regenerates every block but those two rows
(:func:`test_committed_speed_tables_but_the_train_type_rows_are_regenerated_unchanged`);
``VTOOL_SLOW_TESTS=1`` adds the whole regeneration, those rows included
(:func:`test_committed_speed_tables_are_regenerated_unchanged`), as ``python3 benchmarks/sweep_docs.py``
writes it.
"""

from __future__ import annotations

import importlib.util
import os
from pathlib import Path

import pytest

from vtool.markdown import read_block

ROOT = Path(__file__).resolve().parent.parent
#: the presets whose rows of the speeds table only the whole regeneration checks (see the module doc)
SLOW_ROWS = ("direct-acting-bucket", "ohc-finger-follower")


def _generator():  # type: ignore[no-untyped-def]
    spec = importlib.util.spec_from_file_location("sweep_docs", ROOT / "benchmarks" / "sweep_docs.py")
    module = importlib.util.module_from_spec(spec)  # type: ignore[arg-type]
    spec.loader.exec_module(module)  # type: ignore[union-attr]
    return module


@pytest.mark.slow
@pytest.mark.skipif(not os.environ.get("VTOOL_SLOW_TESTS"), reason="a minute or more: VTOOL_SLOW_TESTS=1")
def test_committed_speed_tables_are_regenerated_unchanged() -> None:
    for name, text in _generator().deterministic_blocks().items():
        assert read_block(ROOT / "docs" / "sweep.md", name) == text, f"{name}: run python3 benchmarks/sweep_docs.py"


def _without_slow_rows(table: str) -> str:
    return "".join(line for line in table.splitlines(keepends=True)
                   if not any(line.startswith(f"| `{name}` |") for name in SLOW_ROWS))


def test_committed_speed_tables_but_the_train_type_rows_are_regenerated_unchanged() -> None:
    """Every generated block of docs/sweep.md regenerated; of the speeds table, every row but SLOW_ROWS'."""
    generator = _generator()  # a fresh module of its own: its preset list is this test's to narrow
    assert {name for name, _ in generator.PRESETS} >= set(SLOW_ROWS)
    generator.PRESETS = tuple((name, words) for name, words in generator.PRESETS if name not in SLOW_ROWS)
    blocks = generator.deterministic_blocks()
    committed = read_block(ROOT / "docs" / "sweep.md", "sweep-speeds")
    assert len(_without_slow_rows(committed).splitlines()) == len(committed.splitlines()) - len(SLOW_ROWS)
    for name, text in blocks.items():
        expected = read_block(ROOT / "docs" / "sweep.md", name)
        if name == "sweep-speeds":
            expected = _without_slow_rows(expected)
        assert expected == text, f"{name}: run python3 benchmarks/sweep_docs.py"
