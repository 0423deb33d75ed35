"""Several valves on one camshaft (solvers/studies/camshaft.py, presets/camshaft.py, `vtool camshaft`)."""

from __future__ import annotations

import json

import numpy as np
import pytest
from click.testing import CliRunner
from hypothesis import given, settings
from hypothesis import strategies as st

from vtool.errors import InputError
from vtool.presets.camshaft import load
from vtool.solvers.studies.camshaft import cylinder_phases, sum_valves

STEP = 1.0
GRID = np.arange(360) * STEP


def _valve_torque(theta_deg: np.ndarray) -> np.ndarray:
    """A lobe's torque: positive while opening, negative while closing, zero on the base circle, with
    orders 1..40 (event 120 deg)."""
    x = np.mod(theta_deg + 60.0, 360.0)
    return np.where(x < 120.0, np.sin(2.0 * np.pi * x / 120.0) * (1.0 + 0.3 * np.sin(np.radians(x) * 9.0)), 0.0)


@settings(max_examples=15, deadline=None)
@given(st.integers(1, 8), st.floats(-180.0, 180.0))
def test_identical_phased_valves_sum_shifted_and_cancel_orders(n, offset_whole):
    offset = round(offset_whole)  # whole degrees: the grid's shift is exact
    single = _valve_torque(GRID)
    phases = [offset + 360.0 * k / n for k in range(n)] if 360 % n == 0 else [offset] * n
    result = sum_valves([f"v{k}" for k in range(n)], [(GRID, single)] * n, phases, STEP, "N*mm", 3000.0)
    expected = sum(_valve_torque(GRID - p) for p in phases)
    assert np.max(np.abs(result.torque - expected)) <= 1e-12 * n
    assert np.isclose(result.torque.mean(), n * single.mean(), atol=1e-12)
    if 360 % n == 0:
        spectrum = result.spectrum()
        biggest = spectrum.amplitude.max()
        for k, amplitude in enumerate(spectrum.amplitude):
            if k % n:
                assert amplitude <= 1e-9 * biggest, (k, amplitude)
        assert spectrum.amplitude_of(n) > 1e-3 * biggest  # the surviving orders stay


def test_firing_order_gives_cylinder_phases():
    assert cylinder_phases(4, (1, 3, 4, 2)) == {1: 0.0, 3: 90.0, 4: 180.0, 2: 270.0}
    with pytest.raises(InputError, match="camshaft.firing_order"):
        cylinder_phases(4, (1, 3, 3, 2))


def test_camshaft_document_is_checked(tmp_path):
    doc = {"camshaft": {"cylinders": 4, "firing_order": [1, 3, 4, 2],
                        "valves": [{"train": "direct-acting-bucket", "cylinder": 3, "phase": 10.0}]}}
    spec = load(doc, tmp_path)
    assert spec.valves[0].phase_deg == 100.0 and spec.valves[0].train.stem == "direct-acting-bucket"
    doc["camshaft"]["valves"][0]["cylinder"] = 5
    with pytest.raises(InputError, match=r"camshaft.valves\[0\].cylinder"):
        load(doc, tmp_path)
    doc["camshaft"]["valves"][0] = {"train": "no-such-train"}
    with pytest.raises(InputError, match="train"):
        load(doc, tmp_path)


def test_cli_four_cylinder_intake(tmp_path):
    """The shipped camshaft: 8 valves of one train; the sum's mean is 8 times one valve's, its orders below the
    train's own content are multiples of 4 (the four cylinders 90 deg apart)."""
    from vtool.app.cli.main import cli

    out = tmp_path / "torque.csv"
    run = CliRunner().invoke(cli, ["camshaft", "four-cylinder-intake", "--json", "--csv", str(out)])
    assert run.exit_code == 0, run.output
    s = json.loads(run.output)
    assert s["valves"] == 8 and s["torque_unit"] == "N*mm"
    rows = np.loadtxt(out, delimiter=",", skiprows=1)
    assert rows.shape == (360, 10)
    assert np.allclose(rows[:, -1], rows[:, 1:-1].sum(axis=1), rtol=1e-9, atol=1e-4)  # 10 significant digits a cell
    assert np.isclose(s["mean_torque"], 8.0 * rows[:, 1].mean(), rtol=1e-8)
    assert all(o["order"] % 4 == 0 for o in s["orders"])
    bad = CliRunner().invoke(cli, ["camshaft", "nosuch"])
    assert bad.exit_code == 2 and bad.output.count("\n") == 1
