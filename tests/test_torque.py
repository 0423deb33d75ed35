"""Cam drive torque and cam-follower friction (solvers/studies/torque.py) against the lift law's derivatives."""

from __future__ import annotations

import dataclasses
import math
import tomllib
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from vtool.errors import InputError
from vtool.presets import load_document, load_preset
from vtool.solvers.model.camshape import model_lift
from vtool.solvers.model.spec import CamSpec
from vtool.solvers.run import simulate
from vtool.solvers.studies.torque import torque_rows

PRESETS = Path(__file__).resolve().parents[1] / "presets"
HARMONIC = CamSpec(0, 4.0, None, "lift law")  # L = 4 (1 + sin θ): L' = 4 cos θ


def _spec(preset: str, **follower: object):  # type: ignore[no-untyped-def]
    spec = load_preset(preset)
    return dataclasses.replace(spec, follower=dataclasses.replace(spec.follower, **follower))


ANGLES = np.linspace(-30.0, 750.0, 1561)
FORCE = 300.0 + 200.0 * np.sin(np.radians(3.0 * ANGLES))  # any force history: the identity holds row by row


def test_flat_face_torque_is_force_times_lift_slope():
    spec = _spec("direct-acting-bucket", lift=HARMONIC)
    rows = torque_rows(spec, ANGLES, FORCE)
    expected = FORCE * 4.0 * np.cos(np.radians(ANGLES))
    assert np.max(np.abs(rows.torque - expected)) <= 1e-9 * np.max(np.abs(expected))
    assert np.all(rows.friction_force == 0.0) and np.all(rows.friction_power == 0.0)


def test_translating_roller_torque_is_force_times_lift_slope():
    spec = _spec("direct-acting-bucket", lift=HARMONIC, kind="roller", roller_radius=8.0, face_diameter=None)
    rows = torque_rows(spec, ANGLES, FORCE)
    expected = FORCE * 4.0 * np.cos(np.radians(ANGLES))
    assert np.max(np.abs(rows.torque - expected)) <= 1e-9 * np.max(np.abs(expected))
    assert np.all(rows.normal_force >= FORCE)  # F_n = F / cos(pressure angle)


def test_finger_torque_is_force_times_model_lift_slope():
    """Virtual work: the drive torque of a finger follower is F_model d(model lift)/dθ (central difference)."""
    spec = load_preset("ohc-finger-follower")
    theta = np.radians(ANGLES)
    h = 1e-5
    slope = (model_lift(spec.follower, spec.lift_law, theta + h)
             - model_lift(spec.follower, spec.lift_law, theta - h)) / (2.0 * h)
    rows = torque_rows(spec, ANGLES, FORCE)
    assert np.max(np.abs(rows.torque - FORCE * slope)) <= 1e-6 * np.max(np.abs(FORCE * slope))


@settings(max_examples=40, deadline=None)
@given(st.floats(0.0, 0.3), st.floats(-720.0, 720.0), st.floats(0.0, 5e3))
def test_flat_face_friction_power_is_its_torque_times_speed(mu, angle, force):
    """Coulomb sliding at v_s = ω (r_b + L): friction power = ω × the friction's share of the torque."""
    spec = _spec("direct-acting-bucket", lift=HARMONIC, friction=mu)
    rows = torque_rows(spec, np.array([angle]), np.array([force]))
    theta = math.radians(angle)
    lift = 4.0 * (1.0 + math.sin(theta))
    arm = spec.follower.base_radius + lift
    assert math.isclose(rows.friction_force[0], mu * force, rel_tol=1e-12, abs_tol=1e-12)
    assert math.isclose(rows.torque[0], force * 4.0 * math.cos(theta) + mu * force * arm, rel_tol=1e-9,
                        abs_tol=1e-9 * force * 10.0)
    assert math.isclose(rows.friction_power[0], spec.run.omega * mu * force * arm, rel_tol=1e-12, abs_tol=1e-9)


def test_run_reports_torque_and_friction():
    """A run's summary and CSV carry the drive torque and the friction; the cam power over the last revolution
    is the cam contact's work plus the friction's: ∫T dθ = ∫F dL + ∫P dθ/ω (trapezoid over the rows)."""
    spec = _spec("direct-acting-bucket", friction=0.05)
    trace = simulate(spec)
    s = trace.summary()["cam_torque"]
    assert s["torque_unit"] == "N*mm" and s["cycles"] == 1
    assert s["min_torque"] < 0.0 < s["mean_torque"] < s["max_torque"]  # the closing flank gives energy back
    header, _ = trace.csv_columns(())
    names = [h.rpartition(" (")[0] for h in header]
    assert {"cam_torque", "cam_friction_force", "cam_friction_power"} <= set(names)
    text = trace.summary_text()
    assert "cam drive torque over 1 cycle" in text and "cam-follower friction (mu 0.05)" in text
    window = trace.cam_angle >= 360.0 - 1e-6
    angle = np.radians(trace.cam_angle[window])
    force = trace.force("cam")[window]
    rows = torque_rows(spec, trace.cam_angle[window], force)
    lift = model_lift(spec.follower, spec.lift_law, angle)
    cam_work = np.trapezoid(rows.torque, angle)
    parts = np.trapezoid(force * np.gradient(lift, angle), angle) + np.trapezoid(rows.friction_power, angle) / spec.run.omega
    assert math.isclose(cam_work, parts, rel_tol=2e-3)
    assert math.isclose(s["mean_torque"], cam_work / (2.0 * math.pi), rel_tol=1e-3)


def test_follower_friction_field_is_checked():
    doc = tomllib.loads((PRESETS / "direct-acting-bucket.toml").read_text())
    doc["train"]["follower"]["friction"] = 1.5
    with pytest.raises(InputError, match="follower.friction: got 1.5, expected >= 0 and <= 1"):
        load_document(doc)
    doc["train"]["follower"]["friction"] = 0.08
    assert load_document(doc).follower.friction == 0.08


def test_guide_friction_dissipates_force_times_valve_travel():
    """Coulomb guide friction (v_r small): the energy per revolution is F_g times the stem's travel, twice the
    valve's largest lift (up and back down), so the mean power is F_g 2 h_max / T_rev."""
    spec = _spec("direct-acting-bucket", guide_friction=20.0, guide_velocity=1.0)
    trace = simulate(spec)
    s = trace.summary()["cam_torque"]
    keep = trace.cam_angle >= 360.0 - 1e-6
    travel = np.sum(np.abs(np.diff(trace.valve_lift()[keep])))
    lift = trace.valve_lift()[keep].max() - trace.valve_lift()[keep].min()
    assert math.isclose(travel, 2.0 * lift, rel_tol=2e-2)  # the valve goes up and back once (little bounce)
    expected = 20.0 * travel / (2.0 * math.pi / spec.run.omega)
    assert math.isclose(s["mean_guide_friction_power"], expected, rel_tol=2e-2)
    assert "valve guide friction: mean power" in trace.summary_text()
    header, columns = trace.csv_columns(())
    names = [h.rpartition(" (")[0] for h in header]
    force = columns[names.index("valve_guide_friction_force")](slice(None))
    assert np.all(np.abs(force) <= 20.0) and np.max(np.abs(force)) > 19.9
