"""Plate transient windows, signed peaks and the exact reference's truncation, checked at their definitions.

The references are computed here: the Navier series of the simply supported
plate written out in the test (point force P at the centre: modes with m, n
odd, ``w = sum 4 P / (rho h a b w_mn^2) (1 - cos w_mn t)``), and small
synthetic histories whose peak errors are known by construction.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from vtool.assessments.plate.assembly import Plate
from vtool.assessments.plate.study import DEFAULT_PERIODS, window_warnings
from vtool.assessments.plate.transient import (
    exact_histories,
    peak_at_end,
    signed_peak_error_pct,
)
from vtool.presets import PRESET_DIR, load_preset

PLATE = Plate(40.0, 27.0, 0.1, 30.0e6, 0.3, 0.283 / 386.0)


def _point_load_peak_time(periods: float, modes_per_side: int = 60) -> float:
    """t/T of the largest centre deflection under a step point force at the centre (Navier)."""
    D = PLATE.rigidity
    rho_h = PLATE.mass_per_area
    a, b = PLATE.a, PLATE.b
    m = np.arange(1, 2 * modes_per_side, 2, dtype=float)
    mm, nn = np.meshgrid(m, m, indexing="ij")
    w = math.pi**2 * (mm**2 / a**2 + nn**2 / b**2) * math.sqrt(D / rho_h)
    w11 = math.pi**2 * (1 / a**2 + 1 / b**2) * math.sqrt(D / rho_h)
    # W_mn(centre)^2 = 1 for odd m, n; modal mass rho h a b / 4
    coef = (4.0 / (rho_h * a * b * w**2)).ravel()
    period = 2 * math.pi / w11
    t = np.linspace(0.0, periods, 60_001) * period

    def deflection(times: np.ndarray) -> np.ndarray:
        return np.concatenate([(1.0 - np.cos(np.outer(times[lo:lo + 2000], w.ravel()))) @ coef
                               for lo in range(0, times.size, 2000)])

    # every 20th instant first, then every instant within 40 of the three highest of those: the same
    # instant as all 60,001 (checked when this was written: t/T = 1.51685 for 3 periods), a tenth of the work
    coarse = deflection(t[::20])
    near = np.unique(np.clip(np.add.outer(20 * np.argsort(coarse)[-3:], np.arange(-40, 41)), 0, t.size - 1))
    return float(t[near][np.argmax(deflection(t[near]))] / period)


def test_point_load_peak_lies_past_one_and_a_half_periods_and_inside_the_default_window() -> None:
    at = _point_load_peak_time(3.0)
    assert 1.5 < at < 1.55  # the landed 1.5-period window ended just before it
    assert at < DEFAULT_PERIODS - 0.1
    for name in ("plate-table2", "plate-table3", "plate-irs"):
        assert load_preset(PRESET_DIR / f"{name}.toml").study.transient.periods >= at + 0.1


def test_window_check_warns_when_the_peak_is_at_the_end() -> None:
    short = exact_histories(PLATE, "point", 1.5, 100)
    assert peak_at_end(short.displacement, short.tau)
    text = window_warnings({"point": short}, 1.5)
    assert any("point-load displacement peak" in w and "1.5-period window" in w for w in text)
    long = exact_histories(PLATE, "point", DEFAULT_PERIODS, 100)
    assert not peak_at_end(long.displacement, long.tau)
    assert window_warnings({"point": long}, DEFAULT_PERIODS) == []


def test_signed_peak_errors_by_construction() -> None:
    t = np.linspace(0.0, 2.0, 2001)
    exact = np.where(t < 1.0, 2.0 * np.sin(np.pi * t), -1.0 * np.sin(np.pi * (t - 1.0)))
    approx = np.where(t < 1.0, 2.2 * np.sin(np.pi * t), -0.9 * np.sin(np.pi * (t - 1.0)))
    assert signed_peak_error_pct(approx, exact, "+") == pytest.approx(10.0)
    assert signed_peak_error_pct(approx, exact, "-") == pytest.approx(-10.0)
    one_sided = np.abs(exact)  # never negative: no negative peak to report
    assert math.isnan(signed_peak_error_pct(approx, one_sided, "-"))


def test_truncation_of_the_exact_reference_is_measured_with_four_times_the_modes() -> None:
    """The uniform-load acceleration converges slowly: 4N modes move its peak, displacement not."""
    from vtool.assessments.plate.report import truncation_pct

    coarse = exact_histories(PLATE, "uniform", DEFAULT_PERIODS, 50)
    fine = exact_histories(PLATE, "uniform", DEFAULT_PERIODS, 200, tau=coarse.tau)
    t = truncation_pct(coarse, fine)
    assert abs(t["displacement"]) < 0.05
    assert t["acceleration"] < -2.0  # fewer modes under-read the peak
    # the same change computed here from the histories themselves
    a = max(coarse.extreme("acceleration", "+"), -coarse.extreme("acceleration", "-"))  # refined peaks
    b = max(fine.extreme("acceleration", "+"), -fine.extreme("acceleration", "-"))
    assert a >= np.max(np.abs(coarse.acceleration)) and b >= np.max(np.abs(fine.acceleration))
    assert t["acceleration"] == pytest.approx((a - b) / b * 100)
