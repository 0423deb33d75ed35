"""docs/springs.md: its closed-form tables (data sheets, surge, pitch diagram) are what
benchmarks/springs_docs.py gives now (the run tables: `python benchmarks/springs_docs.py --check`)."""

from __future__ import annotations

import importlib.util
from pathlib import Path

from vtool.markdown import read_block

ROOT = Path(__file__).resolve().parent.parent


def test_committed_closed_form_tables_are_regenerated_unchanged() -> None:
    spec = importlib.util.spec_from_file_location("springs_docs", ROOT / "benchmarks" / "springs_docs.py")
    module = importlib.util.module_from_spec(spec)  # type: ignore[arg-type]
    spec.loader.exec_module(module)  # type: ignore[union-attr]
    blocks = module.closed_form_blocks()
    assert set(blocks) == {"springs-sheets", "springs-surge", "springs-pitch", "springs-strength"}
    for name, text in blocks.items():
        assert read_block(ROOT / "docs" / "springs.md", name) == text, \
            f"{name}: run python benchmarks/springs_docs.py --write"
