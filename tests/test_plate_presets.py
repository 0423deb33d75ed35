"""Plate presets: shipped files load, round-trip and run; broken files give one-line errors."""

from __future__ import annotations

import tomllib
from pathlib import Path

import pytest
import tomli_w
from hypothesis import given, settings
from hypothesis import strategies as st

from vtool.errors import InputError
from vtool.presets import PRESET_DIR, load_document, read_document
from vtool.presets import plate as plate_presets

FIXTURES = Path(__file__).parent / "fixtures" / "plate"
SHIPPED = sorted(PRESET_DIR.glob("plate-*.toml"))
BROKEN = sorted(FIXTURES.glob("*.toml"))


def test_presets_exist_for_both_elements() -> None:
    elements = {load_document(read_document(p)).element for p in SHIPPED}
    assert elements == {"bfs16", "mason24"}


@pytest.mark.parametrize("path", SHIPPED, ids=lambda p: p.stem)
def test_shipped_preset_round_trips(path: Path) -> None:
    doc = read_document(path)
    assert doc["kind"] == "plate" and doc["title"] and doc["units"]
    spec = load_document(doc)
    again = plate_presets.load(tomllib.loads(tomli_w.dumps(plate_presets.dump(spec))))
    assert again == spec


@pytest.mark.parametrize("path", BROKEN, ids=lambda p: p.stem)
def test_broken_fixture_gives_its_one_line_error(path: Path) -> None:
    expected = path.read_text(encoding="utf-8").splitlines()[0].removeprefix("# error: ")
    with pytest.raises(InputError) as info:
        load_document(read_document(path))
    message = info.value.one_line()
    assert expected in message
    assert "\n" not in message


def test_table2_case_definitions() -> None:
    spec = load_document(read_document(PRESET_DIR / "plate-table2.toml"))
    sizes = {}
    from vtool.assessments.plate.model import build_model

    for case in spec.study.cases:
        sizes[case.name] = build_model(spec.study.plate, case).size
    assert sizes == {"A1": 64, "A2": 36, "A3": 16, "A4": 36, "A5": 27, "A6": 9, "A7": 20, "A8": 15,
                     "A9": 5, "A10": 5, "A11": 1}


@given(
    a=st.floats(0.01, 1e3), aspect=st.floats(0.011, 90.0), h=st.floats(1e-4, 1.0),
    nu=st.floats(-0.9, 0.49),
    nx=st.sampled_from([4, 8]), method=st.sampled_from(["guyan", "irs"]),
    masters=st.sampled_from(["all", "interior-w", "centre-w", "five-cross-w"]),
)
@settings(max_examples=25, deadline=None)
def test_generated_presets_round_trip(a, aspect, h, nu, nx, method, masters) -> None:
    # within the loader's bounds: sides 1 mm-1 km within a factor 100, h <= half the shorter side
    b = min(max(a * aspect, 1e-3), 1e3)
    h = min(h, 0.5 * min(a, b))
    doc = {
        "kind": "plate", "title": "t", "units": "SI",
        "plate": {"a": a, "b": b, "thickness": h, "youngs_modulus": 2e11, "poisson": nu, "density": 7800.0},
        "study": {"element": "bfs16", "mesh": [nx, nx]},
        "cases": [{"name": "c", "masters": masters, "method": method}, {"name": "u", "masters": ["w@1,1"]},
                  {"name": "h", "auto": 3}],
        "transient": {"cases": ["c"], "omega_max_h": [1.0]},
    }
    spec = plate_presets.load(doc)
    assert plate_presets.load(tomllib.loads(tomli_w.dumps(plate_presets.dump(spec)))) == spec
