"""Exact oscillator response to boom pulses: closed forms, Fourier path, numerical integration."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.integrate import solve_ivp
from scipy.optimize import minimize_scalar

from vtool.assessments.sonic_boom import fourier
from vtool.assessments.sonic_boom.pulses import PULSE_TYPES, Pulse, idealized
from vtool.assessments.sonic_boom.response import end_state, history, peak_response
from vtool.errors import InputError


def n_wave_free(ratio):
    """Free-motion DAF of the symmetric N-wave: 2|sin u/u - cos u|, u = 2 pi tau/T."""
    u = 2.0 * np.pi * np.asarray(ratio, dtype=float)
    return 2.0 * np.abs(np.sin(u) / u - np.cos(u))


def test_symmetric_n_wave_free_daf_matches_closed_form():
    ratio = np.linspace(0.0, 2.5, 2501)[1:]
    res = peak_response(idealized("N", s=2.0), ratio)
    expected = n_wave_free(ratio)
    assert np.max(np.abs(res.velocity.free - expected)) < 1e-9
    assert np.max(np.abs(res.displacement.free - expected)) < 1e-9


def test_symmetric_n_wave_peak():
    best = minimize_scalar(lambda r: -n_wave_free(r), bounds=(0.3, 0.6), method="bounded",
                           options={"xatol": 1e-10})
    res = peak_response(idealized("N", s=2.0), best.x)
    assert res.velocity.free[0] == pytest.approx(2.126, abs=5e-4)
    assert best.x == pytest.approx(0.436, abs=1e-3)
    assert res.velocity.overall[0] == res.velocity.free[0]


def test_n_wave_forced_phase_reported_separately_and_exact():
    # forced phase, velocity: v = sin(theta) - (1 - cos theta)/u on [0, 2u]
    for ratio in (0.1, 0.33, 0.436, 1.0, 2.3):
        u = 2.0 * math.pi * ratio
        res = peak_response(idealized("N", s=2.0), ratio)
        th = np.linspace(0.0, 2.0 * u, 200_001)
        v = np.sin(th) - (1.0 - np.cos(th)) / u
        x = (1.0 - np.cos(th)) - (th - np.sin(th)) / u
        assert res.velocity.forced[0] >= np.max(np.abs(v)) - 1e-12
        assert res.velocity.forced[0] == pytest.approx(np.max(np.abs(v)), abs=1e-8)
        assert res.displacement.forced[0] == pytest.approx(np.max(np.abs(x)), abs=1e-8)
        assert res.velocity.forced[0] != pytest.approx(res.velocity.free[0], abs=1e-6)
        # the reported instant is where that peak is
        at = res.velocity.forced_at[0] * u
        assert abs(math.sin(at) - (1.0 - math.cos(at)) / u) == pytest.approx(res.velocity.forced[0])


def test_resonant_full_sine_cycle_is_exact():
    # Q with s = 2, alpha = 1 at tau/T = 0.5 is one cycle of sin(omega t): amplitude pi
    res = peak_response(idealized("Q", s=2.0, alpha=1.0), np.array([0.5, 0.5 * (1 + 1e-13)]))
    assert res.velocity.free == pytest.approx([math.pi, math.pi], abs=1e-10)
    assert fourier.free_amplitude(idealized("Q", s=2.0), 0.5)[0] == pytest.approx(math.pi, abs=1e-12)


def test_zero_duration_gives_zero_and_negative_is_an_error():
    res = peak_response(idealized("N"), np.array([0.0, 0.5]))
    assert res.velocity.overall[0] == 0.0 and res.velocity.overall[1] > 0.0
    with pytest.raises(InputError):
        peak_response(idealized("N"), -0.1)
    with pytest.raises(InputError):
        peak_response(idealized("N"), 0.5, damping=1.0)


@st.composite
def pulses(draw):
    kind = draw(st.sampled_from(PULSE_TYPES))
    s = draw(st.floats(1.0, 2.6))
    r1 = draw(st.floats(0.01, 0.9)) if kind in ("P", "T") else 0.0
    r2 = None
    alpha = beta = None
    if kind == "P":
        r2 = draw(st.floats(0.0, 1.0)) * (s - 1.0)
    if kind == "T":
        r2 = draw(st.floats(0.0, 0.5))
        alpha = draw(st.floats(0.0, 1.0))
        beta = draw(st.floats(-0.5, 0.5))
    if kind in ("Q", "R"):
        alpha = draw(st.floats(0.0, 1.5))
    return idealized(kind, s=s, r1=r1, r2=r2, alpha=alpha, beta=beta)


ratios = st.lists(st.floats(0.01, 2.5), min_size=1, max_size=8).map(np.array)


@settings(max_examples=150, deadline=None)
@given(pulse=pulses(), ratio=ratios)
def test_free_velocity_daf_equals_free_displacement_daf_and_fourier(pulse, ratio):
    res = peak_response(pulse, ratio)
    assert np.max(np.abs(res.velocity.free - res.displacement.free)) < 1e-9
    assert np.max(np.abs(res.velocity.free - fourier.free_amplitude(pulse, ratio))) < 1e-9
    assert np.all(res.velocity.overall >= res.velocity.forced)


def _integrate(pulse: Pulse, ratio: float, zeta: float, cycles_after: float):
    """Fine-step scipy integration, segment by segment (stopping at every jump)."""
    u = 2.0 * math.pi * ratio
    bounds = pulse.breakpoints() * u
    spans = list(zip(bounds[:-1], bounds[1:], strict=True))
    if cycles_after > 0.0:
        spans.append((bounds[-1], bounds[-1] + 2.0 * math.pi * cycles_after))
    y = np.zeros(2)
    out = {"t": [], "x": [], "v": [], "phase": []}
    for k, (a, b) in enumerate(spans):
        forced = k < len(bounds) - 1
        mid = 0.5 * (a + b) / u
        seg = next((s for s in pulse.segments if s.start <= mid < s.end), None) if forced else None

        def rhs(t, y, seg=seg):
            f = float(seg.pressure(np.array(t / u))) if seg is not None else 0.0
            return [y[1], f - 2.0 * zeta * y[1] - y[0]]

        t_eval = np.linspace(a, b, max(2001, int((b - a) / 5e-4)))
        sol = solve_ivp(rhs, (a, b), y, method="DOP853", rtol=1e-12, atol=1e-14,
                        t_eval=t_eval, max_step=0.05)
        y = sol.y[:, -1]
        out["t"].append(sol.t)
        out["x"].append(sol.y[0])
        out["v"].append(sol.y[1])
        out["phase"].append(np.full(sol.t.size, forced))
    return {k: np.concatenate(v) for k, v in out.items()}


@settings(max_examples=12, deadline=None)
@given(pulse=pulses(), ratio=st.floats(0.05, 2.5), zeta=st.sampled_from([0.0, 0.02, 0.1]))
def test_exact_response_agrees_with_fine_step_integration(pulse, ratio, zeta):
    ref = _integrate(pulse, ratio, zeta, cycles_after=1.5 if zeta == 0.0 else 3.0)
    u = 2.0 * math.pi * ratio
    x, v = history(pulse, ratio, ref["t"] / u, zeta)
    # histories at the same instants (jumps are at segment ends, both sides agree)
    assert np.max(np.abs(x - ref["x"])) < 1e-6
    assert np.max(np.abs(v - ref["v"])) < 1e-6
    res = peak_response(pulse, ratio, zeta)
    forced = ref["phase"]
    for name, series in (("displacement", ref["x"]), ("velocity", ref["v"])):
        pk = res.peaks[name]
        sampled_forced = np.max(np.abs(series[forced]))
        sampled_free = np.max(np.abs(series[~forced]))
        # exact peaks are never below a sample and exceed it by at most the sampling error
        assert sampled_forced - 1e-6 <= pk.forced[0] <= sampled_forced + 1e-6
        assert sampled_free - 1e-6 <= pk.free[0] <= sampled_free + 1e-6


def test_damped_end_state_matches_integration():
    pulse = idealized("R", s=1.9, alpha=0.7)
    ref = _integrate(pulse, 0.8, 0.05, cycles_after=0.0)
    x, v = end_state(pulse, 0.8, 0.05)
    assert x[0] == pytest.approx(ref["x"][-1], abs=1e-9)
    assert v[0] == pytest.approx(ref["v"][-1], abs=1e-9)
