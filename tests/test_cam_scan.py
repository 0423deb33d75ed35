"""Measured cam scans (presets/cam_scan.py): units, crank degrees, valve lift, polylines, smoothing.

The synthetic scan: a polydyne (degree-6 polynomial) lift L = h (1 - u^2)^3,
u = theta / w, over +-w cam degrees around the nose, base circle elsewhere;
sampled at 1 cam degree, Gaussian noise of 0.003 mm rms, quantised to 0.01 mm
(the issue's scan). Its true acceleration is closed form:
L'' = h (-6 (1 - u^2)^2 + 24 u^2 (1 - u^2)) / w^2 (mm/deg^2).
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from vtool.app.cli.main import cli
from vtool.presets import PRESET_DIR
from vtool.presets.cam_scan import (
    ScanSettings,
    chord_noise_rms,
    convert,
    noise_rms,
    per_degree_derivatives,
    prepare,
    series_derivatives,
    smooth,
    smooth_spline,
)

H_MM, W_DEG = 8.0, 70.0  # peak lift, half-width of the event
QUANTUM_MM, NOISE_MM = 0.01, 0.003
#: the stated bounds on the smoothed acceleration's error (mm/deg^2): 20 % and 3 % of the nose's 0.0098
ACC_MAX_ERROR, ACC_RMS_ERROR = 0.002, 0.0003


def polydyne(theta_deg: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Lift (mm) and its acceleration (mm/deg^2), nose at 0 deg."""
    wrapped = (theta_deg + 180.0) % 360.0 - 180.0
    u = np.clip(wrapped / W_DEG, -1.0, 1.0)
    lift = H_MM * (1.0 - u**2) ** 3
    acc = np.where(np.abs(u) < 1.0, H_MM * (-6.0 * (1.0 - u**2) ** 2 + 24.0 * u**2 * (1.0 - u**2)) / W_DEG**2, 0.0)
    return lift, acc


def scan(seed: int, step: float = 1.0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    theta = np.arange(0.0, 360.0, step)
    lift, acc = polydyne(theta)
    noisy = lift + np.random.default_rng(seed).normal(0.0, NOISE_MM, theta.size)
    return theta, np.round(noisy / QUANTUM_MM) * QUANTUM_MM, acc


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_smoothing_recovers_the_acceleration_of_a_noisy_quantised_scan(seed: int) -> None:
    theta, measured, true_acc = scan(seed)
    _, raw_acc = per_degree_derivatives(theta, measured)
    assert np.abs(raw_acc - true_acc).max() > 5 * ACC_MAX_ERROR  # the raw second differences are noise
    result = smooth(theta, measured)
    _, acc = series_derivatives(theta, result.lift)
    error = acc - true_acc
    assert np.abs(error).max() <= ACC_MAX_ERROR
    assert np.sqrt(np.mean(error**2)) <= ACC_RMS_ERROR
    # the peak within the stated tolerance (4 x the noise rms by default), and the move reported
    assert abs(result.peak_smoothed - result.peak_raw) <= result.peak_tolerance
    assert result.peak_tolerance == pytest.approx(4.0 * result.noise_rms)
    moved = result.lift - measured
    assert result.moved_max == pytest.approx(np.abs(moved).max()) and result.moved_rms == pytest.approx(
        np.sqrt(np.mean(moved**2)))
    assert 0.002 < result.noise_rms < 0.006  # mm: the noise and the quantisation, sqrt(0.003^2 + 0.01^2/12)
    assert 8 <= result.harmonics <= 40


def test_noise_estimate_of_white_noise() -> None:
    noise = np.random.default_rng(7).normal(0.0, 0.05, 3600)
    assert noise_rms(noise) == pytest.approx(0.05, rel=0.1)


def test_a_tight_peak_tolerance_raises_the_cut_off() -> None:
    theta, measured, _ = scan(4)
    loose = smooth(theta, measured)
    tight = smooth(theta, measured, peak_tolerance=0.2 * abs(loose.peak_smoothed - loose.peak_raw) + 1e-9)
    assert tight.raised and tight.harmonics > loose.harmonics
    assert abs(tight.peak_smoothed - tight.peak_raw) <= tight.peak_tolerance


def test_conversions_of_a_crank_degree_thou_valve_lift_scan() -> None:
    settings = ScanSettings(lift_unit="thou", angle="crank", lift_of="valve", rocker_ratio=1.5)
    theta, lift, notes = convert([0.0, 2.0, 4.0], [150.0, 300.0, 600.0], settings, "in", 0.0254)
    assert theta.tolist() == [0.0, 1.0, 2.0]
    assert lift == pytest.approx([0.1, 0.2, 0.4])  # thou -> in, / 1.5
    assert notes == ["lift in thou converted to in (x 0.001)",
                     "crank degrees halved to cam degrees (four-stroke: 2 crank revolutions per cam revolution)",
                     "valve lift divided by the rocker ratio 1.5 to tappet lift"]
    theta, lift, notes = convert([0.0, 1.0], [1.0, 2.0], ScanSettings(lift_unit="mm"), "m", 1.0)
    assert lift == pytest.approx([1e-3, 2e-3]) and notes[0] == "lift in mm converted to m (x 0.001)"


def test_a_partial_scan_is_extended_with_the_base_circle() -> None:
    theta, lift = np.arange(0.0, 181.0), polydyne(np.arange(0.0, 181.0) - 90.0)[0]
    result = prepare(theta.tolist(), lift.tolist(), ScanSettings(lift_unit="mm", smoothing="fourier"), "mm", 1e-3)
    assert result.angles.size == 360 and np.all(result.raw[181:] == 0.0)
    assert any("covers 180 of 360 cam deg" in n for n in result.notes)


def preset_text(table_line: str, scan_table: str) -> str:
    text = (PRESET_DIR / "ramped-cam.toml").read_text()
    text = re.sub(r"^lift_table = .*$", table_line, text, count=1, flags=re.M)
    text = re.sub(r"^tolerance = .*\n", "", text, count=1, flags=re.M)  # harmonics: the smoothing's cut-off
    return text.replace("\n[seat]\n", f"\n{scan_table}\n[seat]\n", 1)


SCAN_TABLE = """[cam.scan]
lift_unit = "thou"
angle = "crank"
lift_of = "valve"
rocker_ratio = 1.5
smoothing = "fourier"
"""


def write_valve_scan(folder: Path) -> tuple[np.ndarray, np.ndarray]:
    """The synthetic scan as a measuring machine writes it: crank degrees, valve lift in thou."""
    theta, measured, _ = scan(5)
    crank = 2.0 * theta
    valve_thou = measured * 1.5 / 0.0254  # mm of tappet lift -> thou of valve lift
    rows = "\n".join(f"{a:g},{v:.4f}" for a, v in zip(crank, valve_thou, strict=True))
    (folder / "scan.csv").write_text(f"crank angle (deg),valve lift (thou)\n{rows}\n")
    return theta, measured


def test_the_loader_says_what_it_converted_and_smoothed(tmp_path: Path) -> None:
    from vtool.presets import load_preset

    theta, measured = write_valve_scan(tmp_path)
    preset = tmp_path / "scan.toml"
    preset.write_text(preset_text('lift_table = "scan.csv"', SCAN_TABLE))
    result = CliRunner().invoke(cli, ["cam", "show", str(preset)])
    assert result.exit_code == 0, result.output
    notes = [line for line in result.output.splitlines() if line.startswith("note: ")]
    assert len(notes) == 1
    assert notes[0].startswith("note: cam: lift in thou converted to in (x 0.001); crank degrees halved to cam "
                               "degrees (four-stroke: 2 crank revolutions per cam revolution); valve lift divided "
                               "by the rocker ratio 1.5 to tappet lift; smoothed by a Fourier series of")
    assert "lift moved by at most" in notes[0] and "peak" in notes[0]
    spec = load_preset(preset)
    assert np.asarray(spec.cam.angles) == pytest.approx(theta)
    # the smoothed tappet lift (in) is the scan (mm / 25.4) within a few quanta
    assert np.abs(np.asarray(spec.cam.lifts) - measured / 25.4).max() < 3 * QUANTUM_MM / 25.4
    assert spec.cam.harmonics is not None and spec.cam.lift_table == "scan.csv"


def test_cam_show_draws_raw_against_smoothed(tmp_path: Path) -> None:
    write_valve_scan(tmp_path)
    preset = tmp_path / "scan.toml"
    preset.write_text(preset_text('lift_table = "scan.csv"', SCAN_TABLE))
    out = tmp_path / "scan.svg"
    result = CliRunner().invoke(cli, ["cam", "show", str(preset), "--plot", "--figure", str(out)])
    assert result.exit_code == 0, result.output
    assert "measured scan: raw against smoothed" in result.output
    text = out.read_text()
    for label in ("raw scan", "acceleration (in/deg^2)", "velocity (in/deg)"):
        assert label in text
    assert re.search(r"smoothed \(\d+ harmonics\)", text)


def test_a_polyline_script_is_a_scan(tmp_path: Path) -> None:
    from vtool.presets import load_preset

    theta, measured, _ = scan(6)
    points = " ".join(f"{a:g},{v:.2f}" for a, v in zip(theta, measured, strict=True))
    (tmp_path / "scan.scr").write_text(f"; exported lift, cam deg, mm\n_PLINE {points}\n\n")
    preset = tmp_path / "poly.toml"
    preset.write_text(preset_text('polyline = "scan.scr"',
                                  '[cam.scan]\nlift_unit = "mm"\nsmoothing = "fourier"\n'))
    spec = load_preset(preset)
    assert len(spec.cam.angles) == 360
    assert max(spec.cam.lifts) == pytest.approx(H_MM / 25.4, abs=0.02 / 25.4)


def test_bad_scan_settings_are_one_line(tmp_path: Path) -> None:
    write_valve_scan(tmp_path)
    preset = tmp_path / "bad.toml"
    preset.write_text(preset_text('lift_table = "scan.csv"', SCAN_TABLE.replace("rocker_ratio = 1.5\n", "")))
    result = CliRunner().invoke(cli, ["cam", "show", str(preset)])
    assert result.exit_code == 2
    assert "cam.scan.rocker_ratio" in result.output and "valve-lift scan" in result.output
    preset.write_text(preset_text('lift_table = "scan.csv"', SCAN_TABLE.replace('"thou"', '"furlong"')))
    result = CliRunner().invoke(cli, ["cam", "show", str(preset)])
    assert result.exit_code == 2 and "cam.scan.lift_unit" in result.output and "thou" in result.output
    (tmp_path / "bad.scr").write_text("PLINE 0,0 1;2\n")
    preset.write_text(preset_text('polyline = "bad.scr"', '[cam.scan]\nlift_unit = "mm"\n'))
    result = CliRunner().invoke(cli, ["cam", "show", str(preset)])
    assert result.exit_code == 2 and "cam.polyline line 1" in result.output


def irregular_scan(seed: int) -> tuple[np.ndarray, np.ndarray]:
    """The polydyne scanned at unequal steps (about 0.86 deg on average, to 0.01 deg), same noise and quanta."""
    rng = np.random.default_rng(seed)
    theta = np.unique(np.round(np.sort(rng.uniform(0.0, 360.0, 420)), 2))
    noisy = polydyne(theta)[0] + rng.normal(0.0, NOISE_MM, theta.size)
    return theta, np.round(noisy / QUANTUM_MM) * QUANTUM_MM


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_spline_smoothing_of_an_unequal_step_scan_meets_the_fourier_bounds(seed: int) -> None:
    """The spline method, on a scan the Fourier method refuses (unequal steps): the same acceleration bounds
    (max 0.002, rms 0.0003 mm/deg^2) on the series the dynamics uses, the peak within its tolerance, the
    move reported at the scan's own points."""
    theta, measured = irregular_scan(seed)
    _, raw_acc = per_degree_derivatives(theta, measured)
    _, true_raw = polydyne(theta)
    assert np.abs(raw_acc - true_raw).max() > 5 * ACC_MAX_ERROR  # the raw divided differences are noise
    result = smooth_spline(theta, measured)
    count = result.angles.size  # sampled at the median step, rounded to divide 360
    assert count == round(360.0 / np.median(np.diff(theta))) and np.allclose(np.diff(result.angles), 360.0 / count)
    _, acc = series_derivatives(result.angles, result.lift)
    error = acc - polydyne(result.angles)[1]
    assert np.abs(error).max() <= ACC_MAX_ERROR
    assert np.sqrt(np.mean(error**2)) <= ACC_RMS_ERROR
    assert abs(result.peak_smoothed - result.peak_raw) <= result.peak_tolerance
    assert result.peak_tolerance == pytest.approx(4.0 * result.noise_rms)
    assert 0.002 < result.noise_rms < 0.006  # sqrt(0.003^2 + 0.01^2/12) = 0.0042 mm
    assert result.moved_rms == pytest.approx(result.noise_rms, rel=1e-3)  # the discrepancy principle
    assert 8 <= result.harmonics <= 60
    X = np.fft.rfft(result.lift)
    X[result.harmonics + 1:] = 0.0
    assert np.abs(np.fft.irfft(X, result.lift.size) - result.lift).max() <= result.noise_rms / 4


def test_chord_noise_estimate_of_white_noise_at_unequal_steps() -> None:
    rng = np.random.default_rng(8)
    theta = np.unique(np.sort(rng.uniform(0.0, 360.0, 3000)))
    assert chord_noise_rms(theta, rng.normal(0.0, 0.05, theta.size)) == pytest.approx(0.05, rel=0.1)
    assert chord_noise_rms(np.arange(0.0, 360.0, 0.5), np.arange(0.0, 360.0, 0.5) * 0.3) == pytest.approx(0.0)


def test_a_step_that_does_not_divide_360_takes_the_spline(tmp_path: Path) -> None:
    """0.7 deg steps: the Fourier method refuses, naming the spline; smoothing = "spline" loads, the preset's
    table the spline sampled at equal steps, and the note says what it did."""
    from vtool.presets import load_preset

    theta = np.arange(0.0, 359.9, 0.7)
    rng = np.random.default_rng(9)
    measured = np.round((polydyne(theta)[0] + rng.normal(0.0, NOISE_MM, theta.size)) / QUANTUM_MM) * QUANTUM_MM
    rows = "\n".join(f"{a:g},{v:.2f}" for a, v in zip(theta, measured, strict=True))
    (tmp_path / "scan.csv").write_text(f"cam angle (deg),tappet lift (mm)\n{rows}\n")
    preset = tmp_path / "scan.toml"
    preset.write_text(preset_text('lift_table = "scan.csv"', '[cam.scan]\nlift_unit = "mm"\nsmoothing = "fourier"\n'))
    result = CliRunner().invoke(cli, ["cam", "show", str(preset)])
    assert result.exit_code == 2 and 'a step that divides 360 for smoothing = "fourier"' in result.output
    assert 'smoothing = "spline" takes any steps' in result.output
    preset.write_text(preset_text('lift_table = "scan.csv"', '[cam.scan]\nlift_unit = "mm"\nsmoothing = "spline"\n'))
    out = tmp_path / "scan.svg"
    result = CliRunner().invoke(cli, ["cam", "show", str(preset), "--figure", str(out)])
    assert result.exit_code == 0, result.output
    note = next(line for line in result.output.splitlines() if line.startswith("note: "))
    assert "smoothed by a cubic smoothing spline" in note and "sampled at 514 equal steps" in note
    assert "lift moved by at most" in note
    assert re.search(r"smoothed \(spline, \d+ harmonics\)", out.read_text())
    spec = load_preset(preset)
    assert len(spec.cam.angles) == 514 and max(spec.cam.lifts) == pytest.approx(H_MM / 25.4, abs=0.02 / 25.4)


def test_a_partial_scan_is_extended_with_the_base_circle_by_the_spline_too() -> None:
    theta = np.arange(0.0, 181.0, 0.7)
    lift = polydyne(theta - 90.0)[0]
    result = prepare(theta.tolist(), lift.tolist(), ScanSettings(lift_unit="mm", smoothing="spline"), "mm", 1e-3)
    assert result.smoothed is not None and not result.smoothed.periodic
    assert any("covers 180.6 of 360 cam deg" in n for n in result.notes)
    assert np.all(result.lifts[result.angles > 180.6] == 0.0) and result.raw_angles is not None
    assert abs(result.lifts.max() - H_MM) <= result.smoothed.peak_tolerance
