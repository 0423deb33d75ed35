"""Cam lift tables: Fourier fit, derivatives, ramp-junction check, loader (solvers/model/cam.py).

Sources: a trigonometric polynomial sampled at 2K + 1 or more points is
reproduced exactly by the least-squares fit of degree >= K (the basis is
exact); the thesis' harmonic cam is L = A + A sin θ, A = 0.5 in (gnilka-1a).
"""

from __future__ import annotations

import copy
import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from vtool.errors import InputError
from vtool.presets import PRESET_DIR, load_preset, read_document
from vtool.presets.ramped_cam import CSV, table_text
from vtool.presets.valvetrain import dump, load
from vtool.solvers.model.cam import acceleration_jumps, cam_fit, derivatives, fit_table, lift_series

A = 0.5  # in, gnilka-1a


def harmonic_table(angles: np.ndarray) -> np.ndarray:
    return A + A * np.sin(np.radians(angles))


def table_doc(**cam: object) -> dict:
    doc = copy.deepcopy(read_document(PRESET_DIR / "gnilka-1a.toml"))
    doc["cam"] = {"coordinate": 9, "profile": "table", **cam}
    return doc


def test_harmonic_lift_series() -> None:
    c0, a, b = lift_series(load_preset("gnilka-1a").cam)
    assert (c0, a.tolist(), b.tolist()) == (A, [0.0], [A])


@pytest.mark.parametrize("spacing", ["uniform", "random"])
def test_table_of_the_harmonic_cam_gives_back_the_harmonic_series(spacing: str) -> None:
    rng = np.random.default_rng(1)
    angles = np.arange(0.0, 360.0, 5.0) if spacing == "uniform" else np.sort(rng.uniform(0.0, 360.0, 90))
    spec = load(table_doc(angles=angles.tolist(), lifts=harmonic_table(angles).tolist(), harmonics=8))
    c0, a, b = lift_series(spec.cam)
    assert c0 == pytest.approx(A, abs=1e-12) and b[0] == pytest.approx(A, abs=1e-12)
    assert np.abs(a).max() < 1e-12 and np.abs(b[1:]).max() < 1e-12
    fit = fit_table(angles, harmonic_table(angles), tolerance=1e-9)
    assert fit.harmonics == 1 and fit.max_error < 1e-12


@settings(max_examples=30, deadline=None)
@given(st.integers(1, 6), st.integers(0, 10_000))
def test_trigonometric_polynomials_are_fitted_exactly(K: int, seed: int) -> None:
    rng = np.random.default_rng(seed)
    a, b = rng.normal(size=K), rng.normal(size=K)
    angles = np.sort(rng.choice(np.arange(0.0, 360.0, 0.5), size=4 * K + 5, replace=False))
    lifts = derivatives(0.3, a, b, np.radians(angles))[0]
    fit = fit_table(angles, lifts, harmonics=K + 1)
    assert fit.c0 == pytest.approx(0.3, abs=1e-8)
    np.testing.assert_allclose(fit.a[:K], a, atol=1e-8)
    np.testing.assert_allclose(fit.b[:K], b, atol=1e-8)
    assert abs(fit.a[K]) < 1e-8 and abs(fit.b[K]) < 1e-8


def test_derivatives_of_the_harmonic_cam() -> None:
    theta = np.linspace(0.0, 2 * math.pi, 7)
    L, v, acc, jerk = derivatives(A, np.zeros(1), np.array([A]), theta)
    np.testing.assert_allclose(L, A + A * np.sin(theta), atol=1e-15)
    np.testing.assert_allclose(v, A * np.cos(theta), atol=1e-15)
    np.testing.assert_allclose(acc, -A * np.sin(theta), atol=1e-15)
    np.testing.assert_allclose(jerk, -A * np.cos(theta), atol=1e-15)


def ramp_flank_table(junction_deg: float, step: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """Dwell, constant-velocity ramp from 20 deg, a parabolic flank from ``junction_deg``, mirrored at 180.

    On the rising side the acceleration is 0 on the ramp and jumps to 2 c at
    the junction; the velocity jumps where the ramp leaves the dwell (20 deg).
    """
    angles = np.arange(0.0, 360.0, step)
    theta = np.radians(np.minimum(angles, 360.0 - angles))
    t0, t1 = math.radians(20.0), math.radians(junction_deg)
    v, c = 0.02, 0.05
    lift = np.where(theta < t0, 0.0, v * (theta - t0))
    lift = np.where(theta >= t1, v * (t1 - t0) + v * (theta - t1) + c * (theta - t1) ** 2, lift)
    return angles, lift


@pytest.mark.parametrize("junction", [40.0, 40.5, 63.0])
def test_a_ramp_junction_is_flagged_at_its_angle(junction: float) -> None:
    angles, lift = ramp_flank_table(junction)
    jumps = [j for j in acceleration_jumps(angles, lift) if j.angle_deg < 170.0]
    assert [j.kind for j in jumps] == ["velocity", "acceleration"]
    assert jumps[0].angle_deg == 20.0
    assert jumps[1].angle_deg == pytest.approx(junction, abs=0.5)
    assert jumps[1].jump == pytest.approx(0.1, rel=0.05)  # 2 c in in/rad²
    mirrored = [j for j in acceleration_jumps(angles, lift) if j.angle_deg > 190.0]
    assert [round(j.angle_deg, 6) for j in mirrored] == [round(360.0 - junction, 6), 340.0]


def test_smooth_tables_are_not_flagged() -> None:
    angles = np.arange(0.0, 360.0, 2.0)
    assert acceleration_jumps(angles, harmonic_table(angles)) == []
    ramped = load_preset("ramped-cam").cam
    assert acceleration_jumps(np.array(ramped.angles), np.array(ramped.lifts)) == []


def test_shipped_ramped_cam_table_is_what_its_script_writes() -> None:
    assert CSV.read_text(encoding="utf-8") == table_text()


def test_ramped_cam_fit_meets_its_tolerance_and_round_trips() -> None:
    spec = load_preset("ramped-cam")
    fit = cam_fit(spec.cam)
    assert fit.max_error <= spec.cam.tolerance and fit.harmonics == 26
    assert max(spec.cam.lifts) == pytest.approx(0.40)
    assert load(dump(spec)) == spec


def test_lift_table_file_is_resolved_against_the_preset_folder(tmp_path: Path) -> None:
    angles = np.arange(0.0, 360.0, 10.0)
    rows = "\n".join(f"{a:g}, {lift:.12f}" for a, lift in zip(angles, harmonic_table(angles), strict=True))
    (tmp_path / "lift.csv").write_text("# scanned\nangle_deg,lift_in\n" + rows + "\n")
    doc = table_doc(lift_table="lift.csv", harmonics=3)
    import tomli_w

    (tmp_path / "cam.toml").write_text(tomli_w.dumps(doc))
    spec = load_preset(str(tmp_path / "cam.toml"))
    assert lift_series(spec.cam)[2][0] == pytest.approx(A, abs=1e-9)


@pytest.mark.parametrize(
    ("cam", "message"),
    [
        ({"lift_table": "missing.csv", "harmonics": 3}, "cam.lift_table"),
        ({"lift_table": ".", "harmonics": 3}, "regular file"),
        ({"angles": [0, 90, 90, 270], "lifts": [0, 1, 1, 0], "harmonics": 1}, "strictly increasing"),
        ({"angles": [0, 90, 180, 270], "lifts": [0, 1, 1], "harmonics": 1}, "as many lifts"),
        ({"angles": [0, 90, 180, 270], "lifts": [0, 1, 1, 0], "harmonics": 2}, "1..1"),
        ({"angles": [0, 90, 180, 270], "lifts": [0, 1, 1, 0]}, "either harmonics"),
        ({"angles": [0, 90, 180, 270], "lifts": [0, 1, 1, 0], "harmonics": 1, "tolerance": 0.1}, "either"),
        ({"angles": [0, 90, 180, 270], "lifts": [0, -1, 1, 0], "harmonics": 1}, "lifts >= 0"),
        ({"angles": [0, 90, 180, 270], "lifts": [0, 1, 0.5, 0], "tolerance": 1e-9}, "cam.tolerance"),
    ],
)
def test_bad_tables_are_one_line_input_errors(cam: dict, message: str, tmp_path: Path) -> None:
    with pytest.raises(InputError) as info:
        load(table_doc(**cam), folder=tmp_path)
    assert message in info.value.one_line()


def test_table_of_the_harmonic_cam_reproduces_the_harmonic_run() -> None:
    """Exact back end: the table cam fitted from 72 samples of A + A sin θ runs as the thesis' cam."""
    from dataclasses import replace

    from vtool.solvers.run import simulate

    thesis = load_preset("gnilka-1a")
    thesis = replace(thesis, run=replace(thesis.run, backend="exact", degrees=400.0))
    angles = np.arange(0.0, 360.0, 5.0)
    doc = table_doc(angles=angles.tolist(), lifts=harmonic_table(angles).tolist(), harmonics=4)
    table = load(doc)
    table = replace(table, run=thesis.run)
    a, b = simulate(thesis), simulate(table)
    assert [(e.clearance, e.kind) for e in a.events] == [(e.clearance, e.kind) for e in b.events]
    assert max(abs(x.cam_angle - y.cam_angle) for x, y in zip(a.events, b.events, strict=True)) < 1e-6


def test_loading_a_table_with_a_ramp_junction_warns_naming_the_angle() -> None:
    """Issue 15: not only `vtool cam show`: loading (hence `vtool solve`) warns where the table jumps."""
    from vtool.errors import PresetWarning

    angles, lift = ramp_flank_table(40.0)
    doc = table_doc(angles=angles.tolist(), lifts=lift.tolist(), harmonics=40)
    with pytest.warns(PresetWarning) as caught:
        load(doc)
    messages = [str(w.message) for w in caught if issubclass(w.category, PresetWarning)]
    assert len(messages) == 1
    assert messages[0].startswith("cam: the lift table's acceleration jumps at 20 deg (velocity kink), 40 deg,")
    assert "320 deg, 340 deg (velocity kink)" in messages[0]


def test_a_smooth_table_loads_without_a_junction_warning() -> None:
    import warnings

    from vtool.errors import PresetWarning

    with warnings.catch_warnings():
        warnings.simplefilter("error", PresetWarning)
        load_preset("ramped-cam")
        angles = np.arange(0.0, 360.0, 5.0)
        load(table_doc(angles=angles.tolist(), lifts=harmonic_table(angles).tolist(), harmonics=4))


def test_vtool_solve_prints_one_warning_line_naming_the_junction(tmp_path: Path) -> None:
    import tomli_w
    from click.testing import CliRunner

    from vtool.app.cli.main import cli

    angles, lift = ramp_flank_table(63.0)
    doc = table_doc(angles=angles.tolist(), lifts=lift.tolist(), harmonics=40)
    doc["seat"]["position"] = 0.56  # in: below where this cam's static start puts the valve
    (tmp_path / "ramp.toml").write_text(tomli_w.dumps(doc))
    result = CliRunner().invoke(cli, ["solve", str(tmp_path / "ramp.toml"), "--degrees", "5"])
    assert result.exit_code == 0, result.output
    warned = [line for line in result.stderr.splitlines() if "lift table" in line]
    assert len(warned) == 1
    assert warned[0].startswith("warning: cam: the lift table's acceleration jumps at 20 deg (velocity kink), 63 deg")
