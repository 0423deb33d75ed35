"""Several valves on one camshaft (solvers/studies/camshaft.py, presets/camshaft.py, `vtool camshaft`)."""

from __future__ import annotations

import json

import numpy as np
import pytest
from click.testing import CliRunner
from hypothesis import given, settings
from hypothesis import strategies as st

from vtool.errors import InputError
from vtool.presets.camshaft import dump, load
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
    doc = {"kind": "camshaft", "camshaft": {"cylinders": 4, "firing_order": [1, 3, 4, 2],
                        "valves": [{"train": "direct-acting-bucket", "cylinder": 3, "phase": 10.0}]}}
    spec = load(doc, tmp_path)
    assert spec.valves[0].phase_deg == 100.0 and spec.valves[0].path.stem == "direct-acting-bucket"
    assert load(dump(spec), tmp_path) == spec  # the TUI's form and a save write what the loader reads back
    doc["camshaft"]["valves"][0]["cylinder"] = 5
    with pytest.raises(InputError, match=r"camshaft.valves\[0\].cylinder"):
        load(doc, tmp_path)
    doc["camshaft"]["valves"][0] = {"train": "no-such-train"}
    with pytest.raises(InputError, match="train"):
        load(doc, tmp_path)


def test_solve_four_cylinder_intake(tmp_path):
    """The shipped camshaft: 8 valves of one train; the sum's mean is 8 times one valve's, its orders below the
    train's own content are multiples of 4 (the four cylinders 90 deg apart)."""
    from vtool.app.cli.main import cli

    out = tmp_path / "torque.csv"
    run = CliRunner().invoke(cli, ["solve", "four-cylinder-intake", "--json", "--csv", str(out)])
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


SMALL = """kind = "camshaft"
title = "two buckets"
[camshaft]
cylinders = 2
firing_order = [2, 1]
[[camshaft.valves]]
train = "direct-acting-bucket"
cylinder = 1
[[camshaft.valves]]
train = "direct-acting-bucket"
cylinder = 2
phase = 30.0
label = "exhaust-ish"
"""


def test_camshaft_is_a_kind_solve_and_the_alias_agree(tmp_path):
    """`vtool solve` runs a camshaft preset through the kinds table; `vtool camshaft` is the same run; --rpm
    is the preset's camshaft.rpm (checked by the loader); the figure's axes name their units."""
    from vtool.app.cli.main import cli

    preset = tmp_path / "two.toml"
    preset.write_text(SMALL)
    figure = tmp_path / "torque.svg"
    solved = CliRunner().invoke(cli, ["solve", str(preset), "--json", "--rpm", "2500", "--figure", str(figure)])
    alias = CliRunner().invoke(cli, ["camshaft", str(preset), "--json", "--rpm", "2500"])
    assert solved.exit_code == 0 and alias.exit_code == 0, solved.output + alias.output
    s = json.loads(solved.stdout)
    assert s == json.loads(alias.stdout)
    assert s["rpm"] == 2500.0 and s["valves"] == 2
    svg = figure.read_text()
    assert "camshaft torque (N*mm)" in svg and "camshaft angle (deg)" in svg and "valve torque (N*mm)" in svg
    # the second valve (cylinder 2 fires first: phase 0, then cylinder 1 at 180 deg) is the first shifted
    text = CliRunner().invoke(cli, ["solve", str(preset)])
    assert "exhaust-ish" in text.output and "30.00" in text.output and "180.00" in text.output
    bad = CliRunner().invoke(cli, ["solve", str(preset), "--rpm", "0"])
    assert bad.exit_code == 2 and "--rpm" in bad.output and "rev/min" in bad.output
    bad = CliRunner().invoke(cli, ["solve", str(preset), "--dt", "1e-6"])
    assert bad.exit_code == 2 and "camshaft preset" in bad.output
    wrong = CliRunner().invoke(cli, ["camshaft", "gnilka-1a"])
    assert wrong.exit_code == 2 and "camshaft" in wrong.output


def test_torque_figures_are_embedded_and_regenerate():
    """benchmarks/docs_figures.py: docs/torque.md embeds its figures, which exist; the train's redraws (--check)."""
    import sys
    from pathlib import Path

    root = Path(__file__).resolve().parent.parent
    sys.path.insert(0, str(root / "benchmarks"))
    try:
        import docs_figures
    finally:
        sys.path.pop(0)
    assert docs_figures.check([]) == []
    assert {"torque-train", "torque-camshaft"} <= set(docs_figures.PAGES)
    for name, page in docs_figures.PAGES.items():
        assert f"](figures/{name}.png)" in page.read_text()
    assert docs_figures.main(["--check", "--only", "torque-train"]) == 0


def test_hla_charts_carry_the_series_with_units():
    """presets/hla_charts.py: the pressure chart draws the series against cam angle; the pump-up chart the
    extension at each base circle against the cycle and its drift (the differences) from the second cycle."""
    from vtool.app.figures import build_figure
    from vtool.presets.hla_charts import hla_charts
    from vtool.solvers.studies.hla import HLASeries

    angle = np.arange(0.0, 721.0)
    columns = {"hla_pressure": 2.0 + np.sin(np.radians(angle)), "hla_plunger_extension": 0.01 * angle / 720.0}
    units = {"hla_pressure": "MPa", "hla_plunger_extension": "mm"}
    cycles = {"extension": [0.0, 0.05, 0.075, 0.08], "drift": [0.05, 0.025, 0.005]}
    pressure, pump = hla_charts(HLASeries(angle, columns, units, cycles, "mm"), "an HLA train")
    assert pressure.panels[0].ylabel == "chamber pressure (MPa)" and pressure.xlabel == "cam angle (deg)"
    assert np.array_equal(pressure.panels[0].curves[0].y, columns["hla_pressure"])
    assert pressure.panels[1].ylabel == "plunger extension (mm)"
    extension, drift = pump.panels
    assert np.array_equal(extension.curves[0].x, [0, 1, 2, 3, 4]) and np.array_equal(drift.curves[0].x, [2, 3, 4])
    assert np.array_equal(extension.curves[0].y, [0.0, 0.0, 0.05, 0.075, 0.08])  # the start, then each base circle
    assert np.allclose(np.diff(extension.curves[0].y)[1:], drift.curves[0].y)
    assert drift.ylabel == "drift per cycle (mm)"
    labels = [ax.get_ylabel() for ax in build_figure([pressure, pump]).get_axes()]
    assert "chamber pressure (MPa)" in labels and "drift per cycle (mm)" in labels


def test_a_run_with_an_hla_figures_its_pressure_and_pump_up():
    """`vtool solve --figure` of a train with an adjuster (presets/charts.py trace_charts): its chamber pressure
    and pump-up charts join the run's, from the run's own series (a short closed-chamber run)."""
    import dataclasses

    from vtool.presets import PRESET_DIR, load_document, read_document
    from vtool.presets.charts import trace_charts
    from vtool.solvers.run import simulate
    from vtool.solvers.studies.hla import hla_series

    doc = read_document(PRESET_DIR / "ohc-finger-follower-hla.toml")
    doc["train"]["hla"].update(check_conductance=0.0, gap=0.0)
    spec = load_document(doc)
    spec = dataclasses.replace(spec, run=dataclasses.replace(spec.run, cycles=0, degrees=30.0))
    trace = simulate(spec)
    charts = {c.title: c for c in trace_charts(trace)}
    pressure = charts["HLA chamber pressure (MPa)"]
    assert np.array_equal(pressure.panels[0].curves[0].y, hla_series(trace).columns["hla_pressure"])
    assert any(title.startswith("HLA pump-up") for title in charts)
    assert "cam drive torque (N*mm)" in charts
