"""Transient: RK4 against closed forms, exact references, the thesis' peak errors.

Sources: the undamped SDOF step response x = (F/k)(1 − cos ωt); RK4's global
error O(h⁴); RK4's stability interval on the imaginary axis, |z| ≤ 2√2
(thesis eq. 44: 2.8); thesis section 2.4.1 (full 64-DOF model, uniform
step, ω_max h = 1: peak errors about 0 % in displacement, about 2 % in
velocity and about 10 % in acceleration against 200 exact modes; the
point-load acceleration does not converge).
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from vtool.assessments.plate.assembly import Plate
from vtool.assessments.plate.exact import CONVERGED_CHANGE, step_histories, step_response
from vtool.assessments.plate.model import Case, MasterSelection, build_model
from vtool.assessments.plate.transient import (
    RK4_STABILITY_LIMIT,
    exact_histories,
    halving_change_pct,
    peak_error_pct,
    peak_errors,
    rk4_propagator,
    rk4_reference,
    run_modal,
    run_rk4,
    scales,
)

PLATE = Plate(40.0, 27.0, 0.1, 30.0e6, 0.3, 0.283 / 386.0)


def _model(masters: str = "all", element: str = "bfs16"):
    return build_model(PLATE, Case("c", element, 4, 4, MasterSelection(named=masters)))


@given(n=st.integers(1, 5), seed=st.integers(0, 1000), h=st.floats(1e-3, 0.2))
@settings(max_examples=25, deadline=None)
def test_propagator_equals_four_stage_rk4(n, seed, h) -> None:
    rng = np.random.default_rng(seed)
    B = rng.normal(size=(n, n))
    A = B @ B.T + n * np.eye(n)
    g = rng.normal(size=n)
    R, r = rk4_propagator(A, g, h)
    y = np.zeros(2 * n)
    ref = rk4_reference(A, g, h, 20)
    for k in range(20):
        y = R @ y + r
        assert np.allclose(y[:n], ref[k + 1], rtol=1e-10, atol=1e-12)


def test_rk4_fourth_order_on_sdof_step() -> None:
    omega, F = 3.0, 2.0
    errors, hs = [], []
    for steps in (50, 100, 200, 400):
        t_end = 2.0
        h = t_end / steps
        x = rk4_reference(np.array([[omega**2]]), np.array([F]), h, steps)[:, 0]
        t = np.arange(steps + 1) * h
        errors.append(np.max(np.abs(x - F / omega**2 * (1 - np.cos(omega * t)))))
        hs.append(h)
    order = np.polyfit(np.log(hs), np.log(errors), 1)[0]
    assert 3.8 < order < 4.2


def test_rk4_stability_limit_is_two_root_two() -> None:
    def growth(z: float) -> float:
        R, _ = rk4_propagator(np.array([[1.0]]), np.array([0.0]), z)
        return float(np.max(np.abs(np.linalg.eigvals(R))))
    assert growth(2.8) <= 1.0 and growth(RK4_STABILITY_LIMIT * 0.999) <= 1.0
    assert growth(RK4_STABILITY_LIMIT * 1.01) > 1.0


def test_rk4_rejects_steps_above_limit() -> None:
    with pytest.raises(ValueError, match="RK4 stability"):
        run_rk4(PLATE, _model("centre-w"), "uniform", 2.9)


def test_exact_reference_convergence_is_reported() -> None:
    s = scales(PLATE, "uniform")
    t = np.linspace(0, 1.5 * s.period, 3001)
    uniform = step_response(PLATE, "uniform", t, 200)
    point = step_response(PLATE, "point", t, 200)
    assert uniform.change_displacement < 1e-4 and uniform.change_velocity < 0.01
    # converged means a peak that halving the modes moves by at most 1 %: the uniform-load acceleration's
    # terms decay like 1/(mn) and its peak moves 7.5 % from 100 to 200 modes, so it is not
    assert uniform.change_acceleration > CONVERGED_CHANGE
    assert not uniform.acceleration_converged and not point.acceleration_converged
    assert point.change_acceleration > 0.3  # the series diverges: halving the modes halves the peak
    # at t = 0 the uniform-load acceleration is the Fourier series of the uniform load: p0/ρh
    assert uniform.acceleration[0] * PLATE.mass_per_area == pytest.approx(1.0, abs=0.05)
    # the three histories belong together: velocity is the slope of displacement
    dt = t[1] - t[0]
    slope = np.gradient(uniform.displacement, dt)
    assert np.max(np.abs(slope - uniform.velocity)[5:-5]) < 0.02 * np.max(np.abs(uniform.velocity))


@pytest.fixture(scope="module")
def exact_uniform():
    return exact_histories(PLATE, "uniform")


def test_full_model_uniform_step_rk4_at_wh_one_matches_thesis(exact_uniform) -> None:
    errors = peak_errors(run_rk4(PLATE, _model(), "uniform", 1.0), exact_uniform)
    assert abs(errors["displacement"]) < 0.1  # about 0 %
    assert 0.5 < abs(errors["velocity"]) < 3.0  # about 2 %
    assert 7.0 < abs(errors["acceleration"]) < 13.0  # about 10 %


def test_point_load_acceleration_error_not_reported() -> None:
    exact = exact_histories(PLATE, "point", periods=0.5, n_modes=50)
    errors = peak_errors(run_rk4(PLATE, _model("interior-w"), "point", 1.0, 0.5), exact)
    assert np.isnan(errors["acceleration"]) and np.isfinite(errors["velocity"])


@pytest.mark.parametrize("load", ["uniform", "point"])
def test_modal_back_end_is_the_rk4_limit(load: str) -> None:
    model = _model("interior-w-slopes")
    diffs = []
    for wh in (1.0, 0.5, 0.25):
        rk = run_rk4(PLATE, model, load, wh, 0.5)
        mo = run_modal(PLATE, model, load, rk.tau)
        diffs.append(max(np.max(np.abs(getattr(rk, q) - getattr(mo, q))) / np.max(np.abs(getattr(mo, q)))
                         for q in ("displacement", "velocity", "acceleration")))
    assert diffs[2] < 1e-3
    assert diffs[0] / diffs[1] > 8 and diffs[1] / diffs[2] > 8  # fourth order: ~16 per halving


def test_halving_check_shrinks_with_step() -> None:
    model = _model("interior-w")
    coarse = halving_change_pct(PLATE, model, "uniform", 2.0, 0.5)
    fine = halving_change_pct(PLATE, model, "uniform", 0.5, 0.5)
    assert all(fine[q] < coarse[q] for q in coarse)


def test_peak_error_uses_the_larger_extreme_of_the_exact_history() -> None:
    exact = np.array([0.0, 2.0, -1.0, 1.0])
    assert peak_error_pct(np.array([0.0, 1.9, -3.0]), exact) == pytest.approx(-5.0)
    assert peak_error_pct(np.array([0.0, 1.0, -2.2]), -exact) == pytest.approx(10.0)


def test_single_master_model_is_an_sdof_oscillator() -> None:
    """KS = 1: modal integration is (F/K)(1 − cos ωt) exactly."""
    model = _model("centre-w")
    s = scales(PLATE, "uniform")
    tau = np.linspace(0, 1.5, 301)
    resp = run_modal(PLATE, model, "uniform", tau)
    omega = np.sqrt(model.K[0, 0] / model.M[0, 0])
    w = model.centre_row[0] * model.f_uniform[0] / model.K[0, 0] * (1 - np.cos(omega * tau * s.period))
    assert np.allclose(resp.displacement * s.displacement, w, rtol=1e-10, atol=1e-15)


def test_the_exact_peak_is_found_between_its_samples() -> None:
    """The exact series is known at every instant: its peak is refined between the samples, here against a
    grid 10,000 times finer around the extreme sample (the 200-mode acceleration peak was read 0.017 % low)."""
    coarse = exact_histories(PLATE, "uniform", 1.5, 200)
    s = scales(PLATE, "uniform")
    evaluate = step_histories(PLATE, "uniform", 200)
    for index, name in enumerate(("displacement", "velocity", "acceleration")):
        samples = getattr(coarse, name)
        k = int(np.argmax(np.abs(samples)))
        sign = 1.0 if samples[k] > 0 else -1.0
        fine = np.linspace(coarse.tau[k - 1], coarse.tau[k + 1], 20001)
        scale = s.load / (s.displacement, s.velocity, s.acceleration)[index]
        dense = evaluate(fine * s.period)[index] * scale
        best = float(dense.max() if sign > 0 else dense.min())
        refined = coarse.extremes[name][0 if sign > 0 else 1]
        assert sign * refined >= sign * samples[k]
        assert refined == pytest.approx(best, rel=1e-9, abs=1e-12)
    gain = coarse.extremes["acceleration"][0] / coarse.acceleration.max() - 1
    assert gain > 1e-5  # the grid read it low
    # peak errors are measured against the refined exact extreme
    exact_peak = coarse.extremes["displacement"][0]
    assert peak_error_pct(np.array([0.0, 1.01 * exact_peak]), coarse.displacement,
                          coarse.extremes["displacement"]) == pytest.approx(1.0, rel=1e-12)
