"""Cam shape, finger kinematics and contact stress against closed forms (solvers/model/camshape.py, camstress.py)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import brentq

from vtool.solvers.model.camshape import cam_profile, contact, law_derivatives
from vtool.solvers.model.camstress import contact_modulus, film_thickness, hertz_line
from vtool.solvers.model.spec import CamSpec, FingerSpec, FollowerSpec


def table_law(angles_deg: np.ndarray, lifts: np.ndarray, harmonics: int | None = None,
              tolerance: float | None = None) -> CamSpec:
    return CamSpec(0, 0.5 * float(lifts.max()), None, "law", "table", tuple(angles_deg.tolist()),
                   tuple(lifts.tolist()), harmonics, tolerance)


def polydyne(lift: float = 8.0) -> CamSpec:
    from vtool.presets.ramped_cam import ramped_lift

    angles = np.arange(0.0, 360.0, 0.5)
    return table_law(angles, ramped_lift(angles, lift=lift, ramp_height=0.2, ramp_deg=20.0, flank_deg=60.0),
                     tolerance=1e-4)


def test_flat_follower_radius_is_base_plus_lift_plus_acceleration() -> None:
    law = polydyne()
    follower = FollowerSpec("flat", "translating", 20.0, 12.0)
    profile = cam_profile(follower, law)
    L, _, ddL, _ = law_derivatives(law, np.radians(profile.law_angle_deg))
    assert np.abs(profile.curvature_radius - (20.0 + L + ddL)).max() <= 1e-9
    # and the profile is the envelope: every point at distance r_b + L from the centre along its face normal
    psi = np.radians(profile.law_angle_deg)
    normal = np.array([np.sin(psi), np.cos(psi)])  # the face normal in the cam frame
    assert np.abs(profile.x * normal[0] + profile.y * normal[1] - (20.0 + L)).max() <= 1e-9


def eccentric_circle(e: float, circle: float, roller: float, phase: float = 0.3):
    """Radial roller on a circular cam (radius ``circle``, centre ``e`` off the shaft): s(θ) closed form."""
    rho = circle + roller
    angles = np.arange(0.0, 360.0, 0.5)
    t = np.radians(angles) + phase
    s = e * np.sin(t) + np.sqrt(rho**2 - e**2 * np.cos(t) ** 2)
    base = rho - e  # s_min, the pitch radius at the base circle
    return table_law(angles, s - base, harmonics=200), base - roller, phase


def test_roller_pressure_angle_and_pitch_curvature_match_the_eccentric_circle() -> None:
    e, circle, roller = 5.0, 20.0, 10.0
    law, base_radius, phase = eccentric_circle(e, circle, roller)
    follower = FollowerSpec("roller", "translating", base_radius, 10.0, roller_radius=roller)
    theta = np.linspace(0.0, 2 * math.pi, 721)
    c = contact(follower, law, theta)
    # textbook (e.g. Norton, Cam Design and Manufacturing Handbook, the eccentric cam): the pitch curve is a
    # circle of radius R_c + r_r, the normal passes through the circle's centre: sin(alpha) = e cos(t) / (R_c + r_r)
    expected = np.degrees(np.arcsin(e * np.cos(theta + phase) / (circle + roller)))
    assert np.abs(c.pressure_angle_deg - expected).max() <= 1e-9
    assert np.abs(c.curvature_radius - circle).max() <= 1e-9  # the cam profile: the circle itself
    profile = cam_profile(follower, law)
    assert np.abs(profile.curvature_radius - circle).max() <= 1e-9 and profile.undercut == ()


def test_flat_follower_undercut_is_flagged_where_the_radius_turns_negative() -> None:
    # L = h/2 (1 + cos 3ψ): r_b + L + L'' = r_b + h/2 - 4 h cos 3ψ, zero at cos 3ψ = (r_b + h/2) / (4h)
    h, base = 8.0, 10.0
    angles = np.arange(0.0, 360.0, 0.5)
    law = table_law(angles, h / 2 * (1 + np.cos(3 * np.radians(angles))), harmonics=3)
    profile = cam_profile(FollowerSpec("flat", "translating", base, 10.0), law, points=36000)
    edge = math.degrees(math.acos((base + h / 2) / (4 * h)) / 3)
    expected = sorted(((120.0 * k - edge) % 360.0, 120.0 * k + edge) for k in range(3))
    assert len(profile.undercut) == 3
    np.testing.assert_allclose(np.array(profile.undercut), np.array(expected), atol=1e-5)
    assert profile.min_curvature_radius == pytest.approx(base + h / 2 - 4 * h, abs=1e-6)


def test_roller_undercut_where_the_pitch_radius_is_below_the_roller() -> None:
    law = polydyne(lift=8.0)
    small = FollowerSpec("roller", "translating", 15.0, 10.0, roller_radius=2.0)
    large = FollowerSpec("roller", "translating", 15.0, 10.0, roller_radius=30.0)
    p_small, p_large = cam_profile(small, law), cam_profile(large, law)
    assert p_small.undercut == ()
    pitch_radius = p_large.curvature_radius + 30.0
    flagged = (pitch_radius > 0) & (pitch_radius < 30.0)
    assert flagged.any() and p_large.undercut
    for start, end in p_large.undercut:  # every flagged sample lies inside a reported interval
        inside = (p_large.law_angle_deg - start) % 360.0 <= (end - start) % 360.0
        flagged &= ~inside
    assert not flagged.any()


FINGER = FollowerSpec("roller", "finger", 16.0, 10.0, roller_radius=9.0,
                      finger=FingerSpec(roller_arm=20.0, valve_arm=36.0, roller_height=2.0, cam_offset=1.5))
ROCKER = FollowerSpec("roller", "rocker", 16.0, 10.0, roller_radius=9.0,
                      finger=FingerSpec(roller_arm=30.0, valve_arm=45.0, roller_height=2.0, cam_offset=1.0))


def lever_points(follower: FollowerSpec) -> tuple[np.ndarray, np.ndarray]:
    """Roller centre Q0 and cam centre C at the base circle, as FingerSpec's docstring places them."""
    f = follower.finger
    R0 = follower.base_radius + follower.roller_radius
    if follower.arrangement == "rocker":  # roller beyond the pivot, cam below it (y down)
        Q0 = np.array([-f.roller_arm, f.roller_height])
        return Q0, Q0 + np.array([-f.cam_offset, math.sqrt(R0**2 - f.cam_offset**2)])
    Q0 = np.array([f.roller_arm, -f.roller_height])
    return Q0, Q0 + np.array([f.cam_offset, -math.sqrt(R0**2 - f.cam_offset**2)])


def direct_lever(follower: FollowerSpec, law: CamSpec, theta: float) -> tuple[float, float]:
    """(valve lift, roller radial lift) at cam angle θ by bracketing the contact condition (no Newton)."""
    R0 = follower.base_radius + follower.roller_radius
    Q0, C = lever_points(follower)
    ref = math.atan2(*(Q0 - C)[::-1])

    def roller(phi: float) -> np.ndarray:
        return np.array([Q0[0] * math.cos(phi) - Q0[1] * math.sin(phi), Q0[0] * math.sin(phi) + Q0[1] * math.cos(phi)])

    def gap(phi: float) -> float:
        d = roller(phi) - C
        delta = math.atan2(d[1], d[0]) - ref
        return math.hypot(*d) - R0 - float(law_derivatives(law, np.array([theta - delta]))[0, 0])

    phi = brentq(gap, -0.2, 0.8, xtol=1e-16, rtol=1e-15)
    return follower.finger.valve_arm * math.sin(phi), math.hypot(*(roller(phi) - C)) - R0


@pytest.mark.parametrize("follower", [FINGER, ROCKER], ids=["end-pivot finger", "centre-pivot rocker"])
@pytest.mark.parametrize("angle_deg", [-60.0, -40.0, -25.0, 20.0, 45.0, 65.0])
def test_finger_ratio_matches_a_finite_difference_of_the_direct_geometry(follower: FollowerSpec,
                                                                         angle_deg: float) -> None:
    law = polydyne(lift=6.0)
    theta = math.radians(angle_deg)
    c = contact(follower, law, np.array([theta]))
    V, _ = direct_lever(follower, law, theta)
    assert c.valve_lift[0] == pytest.approx(V, abs=1e-10)

    def ratio(h: float) -> float:
        (v1, u1), (v0, u0) = direct_lever(follower, law, theta + h), direct_lever(follower, law, theta - h)
        return (v1 - v0) / (u1 - u0)

    h = 2e-3
    richardson = (4.0 * ratio(h / 2) - ratio(h)) / 3.0
    assert c.ratio[0] == pytest.approx(richardson, rel=1e-8)
    nominal = follower.finger.valve_arm / follower.finger.roller_arm
    assert 0.8 * nominal < c.ratio[0] < 1.2 * nominal  # about the arm ratio, varying with the angle


def test_finger_ratio_varies_and_model_lift_is_the_valve_lift_over_the_nominal_ratio() -> None:
    law = polydyne(lift=6.0)
    c = contact(FINGER, law, np.radians(np.arange(-80.0, 80.0, 1.0)))
    lifting = c.lift > 0.5
    assert np.ptp(c.ratio[lifting]) > 0.01
    np.testing.assert_allclose(c.model_lift, c.valve_lift * 20.0 / 36.0, rtol=0, atol=1e-14)


def test_hertz_roller_on_a_circular_cam_matches_the_closed_form() -> None:
    e, circle, roller, width, force = 5.0, 20.0, 10.0, 12.0, 2500.0
    law, base_radius, _ = eccentric_circle(e, circle, roller)
    follower = FollowerSpec("roller", "translating", base_radius, width, roller_radius=roller,
                            cam_modulus=2.05e5, follower_modulus=2.1e5, cam_poisson=0.3, follower_poisson=0.29)
    c = contact(follower, law, np.linspace(0.0, 2 * math.pi, 73))
    E = 1.0 / ((1 - 0.3**2) / 2.05e5 + (1 - 0.29**2) / 2.1e5)
    R = circle * roller / (circle + roller)
    p0, b = hertz_line(np.full(73, force), width, 1.0 / c.curvature, contact_modulus(2.05e5, 0.3, 2.1e5, 0.29))
    np.testing.assert_allclose(p0, math.sqrt(force * E / (math.pi * width * R)), rtol=1e-9)
    np.testing.assert_allclose(b, math.sqrt(4 * force * R / (math.pi * width * E)), rtol=1e-9)
    np.testing.assert_allclose(p0, 2 * force / width / (math.pi * b), rtol=1e-12)  # p0 = 2 w / (pi b)


def test_dowson_higginson_film_closed_form_and_scaling() -> None:
    E, R, w, u, eta, alpha = 2.2e5, 8.0, 200.0, 5000.0, 1e-8, 0.02  # MPa, mm, N/mm, mm/s, MPa s, 1/MPa
    h = film_thickness(np.array([w * 10.0]), 10.0, np.array([R]), E, np.array([u]), eta, alpha)[0]
    Ep = 2 * E
    expected = 2.65 * R * (eta * u / (Ep * R)) ** 0.7 * (alpha * Ep) ** 0.54 * (w / (Ep * R)) ** -0.13
    assert h == pytest.approx(expected, rel=1e-12)
    h2 = film_thickness(np.array([w * 10.0]), 10.0, np.array([R]), E, np.array([2 * u]), eta, alpha)[0]
    assert h2 / h == pytest.approx(2**0.7, rel=1e-12)
    assert film_thickness(np.array([0.0]), 10.0, np.array([R]), E, np.array([u]), eta, alpha)[0] == 0.0


from hypothesis import given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402


@settings(max_examples=30, deadline=None)
@given(base=st.floats(5.0, 40.0), harmonics=st.lists(st.floats(-1.0, 1.0), min_size=2, max_size=8))
def test_flat_radius_identity_and_envelope_for_any_law(base: float, harmonics: list[float]) -> None:
    """Any smooth periodic law: the profile's curvature radius is r_b + L + L'' wherever the profile is regular."""
    angles = np.arange(0.0, 360.0, 2.0)
    theta = np.radians(angles)
    lift = sum(c * (1 - np.cos((k + 1) * theta)) for k, c in enumerate(harmonics))
    lift = lift - lift.min()
    law = table_law(angles, lift, harmonics=len(harmonics))
    profile = cam_profile(FollowerSpec("flat", "translating", base, 10.0), law, points=720)
    L, _, ddL, _ = law_derivatives(law, np.radians(profile.law_angle_deg))
    rho = base + L + ddL
    regular = np.abs(rho) > 1e-6
    np.testing.assert_allclose(profile.curvature_radius[regular], rho[regular], rtol=1e-9, atol=1e-9)
    assert (len(profile.undercut) > 0) == bool((rho < 0).any())


@settings(max_examples=30, deadline=None)
@given(force=st.floats(1.0, 1e5), radius=st.floats(0.5, 100.0), width=st.floats(1.0, 50.0))
def test_hertz_line_contact_invariants(force: float, radius: float, width: float) -> None:
    E = 1.1e5
    p0, b = hertz_line(np.array([force]), width, np.array([radius]), E)
    assert p0[0] * b[0] * math.pi * width / 2 == pytest.approx(force, rel=1e-12)  # the load the pressure carries
    p4, _ = hertz_line(np.array([4 * force]), width, np.array([radius]), E)
    assert p4[0] == pytest.approx(2 * p0[0], rel=1e-12)
