"""Boom pulse shapes (thesis Figure 1(b) as reconstructed from VELDAF) and their validation."""

from __future__ import annotations

import math

import numpy as np
import pytest

from vtool.assessments.sonic_boom.pulses import (
    PulseParams,
    idealized,
    make_pulse,
    read_pulse_csv,
    tabulated,
)
from vtool.errors import InputError


def _impulse(pulse, positive_only=False):
    """Exact integral of a piecewise-linear pulse (of its positive part if asked)."""
    total = 0.0
    for seg in pulse.segments:
        assert not seg.sinusoidal
        a, b, L = seg.level, seg.slope, seg.length
        if positive_only:
            end = a + b * L
            if a <= 0.0 and end <= 0.0:
                continue
            if a < 0.0 or end < 0.0:  # clip at the zero crossing
                zero = -a / b
                L, a = (L - zero, 0.0) if a < 0.0 else (zero, a)
        total += L * (a + 0.5 * b * L)
    return total


def test_n_wave_is_a_straight_line_through_zero_at_tau():
    p = idealized("N", s=1.8)
    assert p.pressure(0.0) == 1.0
    assert p.pressure(1.0) == pytest.approx(0.0, abs=1e-15)
    assert p.pressure(1.8 - 1e-12) == pytest.approx(-0.8, abs=1e-9)
    assert p.pressure(1.8) == 0.0  # rear shock


def test_p_wave_rise_and_default_rear_rise_keep_the_n_wave_impulse():
    # thesis observation (ii): raising r1 of a P boom keeps its impulse
    n = idealized("N", s=2.2)
    for r1 in (0.1, 0.3, 0.5):
        p = idealized("P", s=2.2, r1=r1)
        assert p.pressure(r1) == pytest.approx(1.0)
        assert p.pressure(1.0) == pytest.approx(0.0, abs=1e-12)
        assert _impulse(p) == pytest.approx(_impulse(n), abs=1e-12)
        assert _impulse(p, positive_only=True) == pytest.approx(0.5, abs=1e-12)
        assert float(p.pressure(np.array([2.2 - (1.2 * r1)]))[0]) == pytest.approx(-1.2, abs=1e-9)


def test_p_with_zero_rise_is_the_n_wave():
    assert idealized("P", s=2.0, r1=0.0).segments == idealized("N", s=2.0).segments


def test_q_and_r_shapes():
    q = idealized("Q", s=2.2)
    assert q.pressure(0.5) == pytest.approx(1.0)
    assert q.pressure(1.6) == pytest.approx(-1.0)
    r = idealized("R", s=1.6, alpha=0.8)
    assert r.pressure(0.0) == pytest.approx(1.0)  # front shock
    assert r.pressure(1.0 - 1e-12) == pytest.approx(0.0, abs=1e-9)
    assert r.pressure(1.6 - 1e-12) == pytest.approx(-0.8, abs=1e-9)


def test_t_wave_peaked_front_and_rear_overshoot():
    t = idealized("T", s=2.0, r1=0.2, alpha=0.5, beta=0.25)
    assert t.pressure(0.0) == 1.0
    assert t.pressure(0.2) == pytest.approx(0.5 * 0.8)
    assert t.pressure(1.0) == pytest.approx(0.0, abs=1e-12)
    assert t.pressure(2.0 - 1e-12) == pytest.approx(-0.5, abs=1e-9)
    assert t.pressure(2.0) == pytest.approx(0.25)
    assert t.duration == pytest.approx(2.2)  # VELDAF: WST1 = WST + WTR2


@pytest.mark.parametrize(
    ("params", "field"),
    [
        (PulseParams("N", s=0.9), "s"),
        (PulseParams("P", s=2.0, r1=1.0), "r1"),
        (PulseParams("P", s=2.0, r1=-0.1), "r1"),
        (PulseParams("P", s=2.0, r1=0.2, r2=1.5), "r2"),
        (PulseParams("T", s=2.0, r1=0.0), "r1"),
        (PulseParams("Q", s=2.0, alpha=-1.0), "alpha"),
        (PulseParams("X"), "type"),
    ],
)
def test_bad_parameters_name_the_field(params, field):
    with pytest.raises(InputError) as err:
        make_pulse(params)
    assert err.value.field == field
    assert "\n" not in str(err.value)


def test_tabulated_pulse_tau_is_the_positive_phase():
    p = tabulated(np.array([0.0, 0.01, 0.06, 0.11]), np.array([0.0, 2.0, -2.0, 0.0]))
    assert p.tau_seconds == pytest.approx(0.035)
    assert p.peak_pressure == 2.0
    assert p.pressure(0.01 / 0.035) == pytest.approx(1.0)


def test_pulse_csv_must_be_monotonic(tmp_path):
    path = tmp_path / "boom.csv"
    path.write_text("time [s],pressure [psi]\n0,0\n0.01,1\n0.005,0\n", encoding="utf-8")
    with pytest.raises(InputError) as err:
        read_pulse_csv(path)
    assert "strictly increasing" in str(err.value)


def test_pulse_csv_round_numbers(tmp_path):
    path = tmp_path / "boom.csv"
    path.write_text("t,p\n0,1\n0.05,0\n0.1,-1\n", encoding="utf-8")
    p = read_pulse_csv(path)
    assert p.tau_seconds == pytest.approx(0.05)
    assert p.duration == pytest.approx(2.0)
    assert math.isclose(float(p.pressure(1.5)), -0.5)
