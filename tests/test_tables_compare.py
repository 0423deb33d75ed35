"""The model-choice tables in docs/valvetrain.md are what `benchmarks/tables_compare.py` writes.

Events and episode counts must match exactly, numbers to two significant
digits (the last digits of a peak force may move with the numpy build).
"""

from __future__ import annotations

import importlib.util
import math
from pathlib import Path

import pytest

from vtool.markdown import read_block

ROOT = Path(__file__).resolve().parent.parent


def load_script():  # noqa: ANN201
    spec = importlib.util.spec_from_file_location("tables_compare", ROOT / "benchmarks" / "tables_compare.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)  # type: ignore[union-attr]
    return module


def cells(block: str) -> list[list[str]]:
    return [[c.strip() for c in line.strip("|").split("|")] for line in block.strip().splitlines()[2:]]


def same(a: str, b: str) -> bool:
    try:
        x, y = float(a), float(b)
    except ValueError:
        return a.split() == b.split() if " " in a or " " in b else a == b
    if x == y:
        return True
    return math.isclose(float(f"{x:.2g}"), float(f"{y:.2g}"), rel_tol=1e-9)


@pytest.mark.slow
@pytest.mark.parametrize("name", ["gnilka-1a", "gnilka-2"])
def test_compare_tables_regenerate(name: str) -> None:
    script = load_script()
    committed = cells(read_block(script.DOC, f"compare-{name}"))
    fresh = cells(script.block(name))
    assert len(committed) == len(fresh)
    for old, new in zip(committed, fresh, strict=True):
        assert len(old) == len(new)
        for a, b in zip(old, new, strict=True):
            if " " in a:  # throw-off angles per revolution
                assert all(same(x, y) for x, y in zip(a.split(), b.split(), strict=True)), (a, b)
            else:
                assert same(a, b), (old, new)
