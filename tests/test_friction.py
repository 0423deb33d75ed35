"""The friction laws of solvers/model/friction.py against hand calculations."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from vtool.solvers.model import friction


def test_coulomb_sharp_and_regularised_by_hand() -> None:
    force, power = friction.coulomb(np.array([-2.0, 0.0, 3.0]), np.array([100.0, 100.0, -5.0]), 0.1)
    assert force.tolist() == [-10.0, 0.0, 0.0]  # sign law; an open contact (N < 0) carries none
    assert power.tolist() == [20.0, 0.0, 0.0]
    force, power = friction.coulomb(np.array([0.5]), np.array([200.0]), 0.05, v_reg=1.0)
    assert math.isclose(force[0], 0.05 * 200.0 * math.tanh(0.5), rel_tol=1e-15)
    assert math.isclose(power[0], force[0] * 0.5, rel_tol=1e-15)


def test_stribeck_by_hand() -> None:
    # mu_c 0.08, mu_s 0.15, v_S 10 mm/s, k_v 1e-4 s/mm; at 10 mm/s: 0.08 + 0.07/e + 0.001
    v = np.array([0.0, 10.0, -1000.0])
    mu = friction.stribeck_coefficient(v, 0.08, 0.15, 10.0, 1e-4)
    assert math.isclose(mu[0], 0.15, rel_tol=1e-15)
    assert math.isclose(mu[1], 0.08 + 0.07 / math.e + 0.001, rel_tol=1e-14)
    assert math.isclose(mu[2], 0.08 + 0.07 * math.exp(-1e4) + 0.1, rel_tol=1e-14)
    force, power = friction.stribeck(v, np.full(3, 50.0), 0.08, 0.15, 10.0, 1e-4)
    assert force[0] == 0.0 and math.isclose(force[1], 50.0 * mu[1]) and math.isclose(force[2], -50.0 * mu[2])
    assert math.isclose(power[2], 1000.0 * 50.0 * mu[2])


def test_pivot_torque_is_mu_f_r_by_hand() -> None:
    # a 4 mm ball, mu 0.1, 800 N reaction: 0.1 * 800 * 4 = 320 N mm against the lever's turning
    torque, power = friction.pivot(np.array([-50.0, 50.0]), np.array([800.0, 800.0]), 0.1, 4.0)
    assert torque.tolist() == [-320.0, 320.0]
    assert power.tolist() == [16000.0, 16000.0]


@settings(max_examples=60, deadline=None)
@given(v=st.floats(-1e3, 1e3), n=st.floats(0.0, 1e4), mu_c=st.floats(0.0, 0.3), extra=st.floats(0.0, 0.3),
       v_s=st.floats(1e-3, 1e3), v_r=st.floats(0.0, 10.0))
def test_friction_never_feeds_power(v: float, n: float, mu_c: float, extra: float, v_s: float, v_r: float) -> None:
    """Every law dissipates: power >= 0, and the force is at most the static coefficient's."""
    force, power = friction.stribeck(np.array([v]), np.array([n]), mu_c, mu_c + extra, v_s, 0.0, v_r)
    assert power[0] >= 0.0 and abs(force[0]) <= (mu_c + extra) * n * (1 + 1e-12)
    torque, power = friction.pivot(np.array([v]), np.array([n]), mu_c, 2.0, v_r)
    assert power[0] >= 0.0


J, R, N, MU, TB = 20.0, 10.0, 100.0, 0.05, 10.0  # g mm^2-ish units: only the ratios matter


def test_roller_rolls_while_the_traction_holds() -> None:
    t = np.linspace(0.0, 1.0, 101)
    u = 500.0 + 10.0 * t  # demand (10 + 20 * 10 / 10) / 10 = 3 <= 5: rolls
    s = friction.roller_slip(t, u, np.full_like(t, N), R, J, TB, MU)
    assert not s.slipping.any()
    np.testing.assert_allclose(s.slip_speed, 0.0, atol=1e-12)
    np.testing.assert_allclose(s.traction, 3.0, rtol=1e-12)
    assert np.all(s.slip_power == 0.0)


def test_roller_slips_at_the_hand_rate_and_sticks_again() -> None:
    """u accelerates at a = 100 for 1 s, then holds: demand (10 + 20*100/10)/10 = 21 > mu N = 5, so the rim
    accelerates at alpha = r (r mu N - T_b) / J = 10 (50 - 10) / 20 = 20; slip speed (a - alpha) t = 80 t;
    after t1 = 1 it falls at alpha: zero at 1 + 80/20 = 5 s, where the steady demand T_b/r = 1 <= 5 rolls."""
    dt = 1e-3
    t = np.arange(0.0, 8.0 + dt / 2, dt)
    u = 500.0 + 100.0 * np.minimum(t, 1.0)
    s = friction.roller_slip(t, u, np.full_like(t, N), R, J, TB, MU)
    early = (t > 0.01) & (t < 0.99)
    np.testing.assert_allclose(s.slip_speed[early], 80.0 * t[early], rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(s.traction[early], MU * N, rtol=1e-12)
    np.testing.assert_allclose(s.slip_power[early], MU * N * 80.0 * t[early], rtol=1e-9, atol=1e-9)
    stick = t[np.argmax(~s.slipping & (t > 1.0))]
    assert abs(stick - 5.0) <= 3 * dt
    assert not s.slipping[t > 5.01].any()
    np.testing.assert_allclose(s.traction[t > 5.01], TB / R, rtol=1e-12)
