"""The boom and plate tables in README.md and docs are what the script writes (regenerated here).

Every column is deterministic (no wall times). Rows that depend on
numpy/scipy name the versions they were made with; the versions cell itself
is not compared, so a version bump that leaves the numbers alone passes and
one that moves a number fails, naming the block.
"""

from __future__ import annotations

import importlib.util
import re
import sys
from pathlib import Path

import pytest

from vtool.markdown import read_block

ROOT = Path(__file__).resolve().parents[1]
_spec = importlib.util.spec_from_file_location("tables_boom_plate", ROOT / "benchmarks" / "tables_boom_plate.py")
tables = importlib.util.module_from_spec(_spec)  # type: ignore[arg-type]
sys.modules["tables_boom_plate"] = tables
_spec.loader.exec_module(tables)  # type: ignore[union-attr]

_VERSIONS = re.compile(r"numpy [0-9][^,|]*, scipy [0-9][^|]*")
_DONE: dict[object, str] = {}


_WALL = re.compile(r"\b\d+(?:\.\d+)? ms\b")  # the console blocks' wall times (plate-console)


def _normal(text: str) -> str:
    return _WALL.sub("T ms", _VERSIONS.sub("numpy X, scipy Y", text))


@pytest.mark.parametrize(("path", "name"), list(tables.BLOCKS), ids=lambda v: getattr(v, "name", v))
def test_committed_block_matches_the_script(path: Path, name: str) -> None:
    fn = tables.BLOCKS[(path, name)]
    if fn not in _DONE:
        _DONE[fn] = fn()
    committed = read_block(path, name)
    assert _normal(committed) == _normal(_DONE[fn]), (
        f"{path.name} block {name!r} differs from the script: run python benchmarks/tables_boom_plate.py")
