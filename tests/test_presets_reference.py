"""docs/presets.md is generated from the loaders' own reads and current; every key has a meaning."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import pytest

from vtool.presets import reference
from vtool.presets.fields import REQUIRED, Table, recording
from vtool.presets.valvetrain import RUN_LIMITS

ROOT = Path(__file__).resolve().parent.parent


@pytest.fixture(scope="module")
def reads() -> dict:
    return reference.field_reads()


def test_every_key_read_has_a_meaning_and_every_meaning_a_key(reads: dict) -> None:
    assert reference.missing_meanings(reads) == [], "keys without a meaning in presets/reference.py MEANINGS"
    assert reference.stale_meanings(reads) == [], "meanings of keys no loader reads"


def test_the_reference_is_current(reads: dict) -> None:
    path = ROOT / "benchmarks" / "presets_reference.py"
    spec = importlib.util.spec_from_file_location("presets_reference", path)
    module = importlib.util.module_from_spec(spec)  # type: ignore[arg-type]
    spec.loader.exec_module(module)  # type: ignore[union-attr]
    assert module.DOC.read_text(encoding="utf-8") == reference.markdown(reads), \
        "run: python benchmarks/presets_reference.py --write"


def test_the_reference_states_the_loaders_ranges_units_and_defaults(reads: dict) -> None:
    run = reads["valvetrain"]
    low, high, unit = RUN_LIMITS["rpm"]
    assert run["run.rpm"].units == {unit} and run["run.rpm"].allowed == {f">= {low:g} and <= {high:g}"}
    assert run["run.rpm"].defaults == {REQUIRED}
    assert run["run.output_interval"].defaults == {"1"}
    assert run["members.*.length"].type == "number"  # a named table's keys under `*`
    assert "clearances[].restitution" in run and "damping.layers[].mode_ratios.<number>" in run
    assert run["members.*.length"].units == {"in", "m", "mm"}  # each unit system a valvetrain preset may declare


def test_recording_notes_each_read_once_with_its_pattern() -> None:
    doc = {"a": {"x": 2.0}, "list": [{"y": 1}, {"y": 2}], "named": {"p": {"z": True}, "q": {"z": False}}}
    with recording() as reads:
        top = Table(doc, "")
        top.table("a").number("x", unit="m", min_value=1.0)  # type: ignore[union-attr]
        for t in top.array_of_tables("list"):
            t.integer("y", default=0, max_value=5)
        for _, t in top.tables("named"):
            t.boolean("z")
    assert set(reads) == {"a", "a.x", "list", "list[].y", "named", "named.*", "named.*.z"}
    assert reads["a.x"].units == {"m"} and reads["a.x"].allowed == {">= 1"}
    assert reads["list[].y"].defaults == {"0"} and reads["list[].y"].allowed == {"<= 5"}
    assert reads["named.*.z"].defaults == {REQUIRED}
    with_nothing = Table({"k": 1.0}, "")
    with_nothing.number("k")  # outside recording(): nothing noted, nothing raised
