"""The friction laws in a run's outputs (solvers/studies/torque.py with solvers/model/friction.py): the Stribeck
flat face, a lever's pivot and a roller's slip against hand formulas; the preset keys (presets/friction.py)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from click.testing import CliRunner

from vtool.errors import InputError
from vtool.presets import load_document, load_preset
from vtool.presets.paths import set_fields
from vtool.presets.valvetrain import dump
from vtool.solvers.model.camshape import contact, model_lift
from vtool.solvers.model.friction import FrictionLaws
from vtool.solvers.model.spec import CamSpec, FingerSpec
from vtool.solvers.studies.torque import row_names, torque_rows

HARMONIC = CamSpec(0, 4.0, None, "lift law")  # L = 4 (1 + sin θ): L' = 4 cos θ
ANGLES = np.linspace(0.0, 360.0, 721)
FORCE = 300.0 + 200.0 * np.sin(np.radians(3.0 * ANGLES))


def _spec(preset: str, **follower: object):  # type: ignore[no-untyped-def]
    spec = load_preset(preset)
    return dataclasses.replace(spec, follower=dataclasses.replace(spec.follower, **follower))


def test_stribeck_flat_face_by_hand() -> None:
    """T = F L' + μ(v_s) F (r_b + L), v_s = ω (r_b + L), μ(v) = μ_c + (μ_s - μ_c) exp(-(v/v_S)²) + k_v v;
    the friction's share of T times ω is its power."""
    laws = FrictionLaws("stribeck", static=0.15, stribeck_velocity=5000.0, viscous=2e-6)
    spec = _spec("direct-acting-bucket", lift=HARMONIC, friction=0.06, laws=laws)
    rows = torque_rows(spec, ANGLES, FORCE)
    theta = np.radians(ANGLES)
    L, dL = 4.0 * (1.0 + np.sin(theta)), 4.0 * np.cos(theta)
    arm = spec.follower.base_radius + L
    v = spec.run.omega * arm
    mu = 0.06 + 0.09 * np.exp(-(v / 5000.0) ** 2) + 2e-6 * v
    np.testing.assert_allclose(rows.friction_force, mu * FORCE, rtol=1e-12)
    np.testing.assert_allclose(rows.torque, FORCE * dL + mu * FORCE * arm, rtol=1e-9, atol=1e-9 * FORCE.max())
    np.testing.assert_allclose(rows.friction_power, spec.run.omega * (rows.torque - FORCE * dL), rtol=1e-9)


def _finger(**laws: float):  # type: ignore[no-untyped-def]
    spec = load_preset("ohc-finger-follower")
    f = spec.follower.finger
    return dataclasses.replace(spec, follower=dataclasses.replace(
        spec.follower, finger=FingerSpec(f.roller_arm, f.valve_arm, 0.0, 0.0), laws=FrictionLaws(**laws)))


def test_pivot_force_at_the_base_circle_and_torque_by_hand() -> None:
    """Roller on the pivot-pad line, cam above it: at the base circle the pivot carries F_n (1 - a/b) (the pad
    carries F_n a/b); the friction torque is μ F_p r_p tanh(Ω/Ω_r), Ω = ω d/dθ arcsin(model lift / a)."""
    spec = _finger(pivot=0.12, pivot_radius=4.0, pivot_velocity=2.0)
    a, b = spec.follower.finger.roller_arm, spec.follower.finger.valve_arm
    rows = torque_rows(spec, ANGLES, FORCE)
    base = np.abs(contact(spec.follower, spec.lift_law, np.radians(ANGLES)).lever_angle) < 1e-6  # (the ramps' foot)
    assert base.sum() > 10
    np.testing.assert_allclose(rows.pivot_force[base], rows.normal_force[base] * (1.0 - a / b), rtol=1e-5)
    theta, h = np.radians(ANGLES), 1e-6
    phi = [np.arcsin(model_lift(spec.follower, spec.lift_law, theta + s) / a) for s in (h, -h)]
    omega = spec.run.omega * (phi[0] - phi[1]) / (2 * h)  # the model coordinate is a sin φ (V a / b)
    expected = 0.12 * rows.pivot_force * 4.0 * np.tanh(omega / 2.0)
    np.testing.assert_allclose(rows.pivot_torque, expected, rtol=1e-5, atol=1e-6 * np.abs(expected).max())
    np.testing.assert_allclose(rows.pivot_power, rows.pivot_torque * omega, rtol=1e-5, atol=1e-3)
    assert np.all(rows.pivot_power >= 0.0)
    assert row_names(spec)[-3:] == ("pivot_force", "pivot_torque", "pivot_power")


def test_roller_slip_in_a_run_rolls_where_the_traction_holds() -> None:
    """Loaded and rolling: the traction is the bearing drag μ F_n plus the roller's inertia J (du/dt) / r²;
    slip power >= 0 everywhere; no slip under a constant rolling speed (the base circle)."""
    spec = _finger(slip=0.3, roller_inertia=4e-4)
    rows = torque_rows(spec, ANGLES, FORCE)
    c = contact(spec.follower, spec.lift_law, np.radians(ANGLES))
    u = spec.run.omega * c.entraining_per_omega
    r = spec.follower.roller_radius
    du = np.gradient(u, np.radians(ANGLES) / spec.run.omega)
    rolling = rows.slip_speed == 0.0
    expected = spec.follower.friction * rows.normal_force + 4e-4 * du / r**2
    np.testing.assert_allclose(rows.friction_force[rolling], expected[rolling], rtol=1e-9, atol=1e-9)
    assert np.all(rows.slip_power >= 0.0) and rolling[np.abs(c.lever_angle) < 1e-6].all()


def test_friction_keys_are_checked_and_round_trip() -> None:
    doc = dump(load_preset("ohc-finger-follower"))
    keys = {"train.follower.pivot_friction": 0.1, "train.follower.pivot_radius": 4.0, "train.follower.slip_friction": 0.2,
            "train.follower.roller_inertia": 4e-4, "train.follower.friction_law": "stribeck", "train.follower.static_friction": 0.2}
    spec = load_document(set_fields(doc, keys))
    assert spec.follower.laws == FrictionLaws("stribeck", static=0.2, stribeck_velocity=10.0, pivot=0.1,
                                              pivot_radius=4.0, slip=0.2, roller_inertia=4e-4)
    assert load_document(dump(spec)) == spec
    for bad, field in (({"train.follower.static_friction": 0.2}, "train.follower.static_friction"),
                       ({"train.follower.friction_law": "stribeck", "train.follower.static_friction": -1}, "static_friction"),
                       ({"train.follower.slip_friction": 0.2}, "train.follower.roller_inertia")):
        with pytest.raises(InputError, match=field):
            load_document(set_fields(doc, bad))


def test_solve_prints_and_writes_the_friction_outputs(tmp_path) -> None:  # type: ignore[no-untyped-def]
    from vtool.app.cli.main import cli

    out = tmp_path / "rows.csv"
    sets = [f"--set=train.follower.{k}" for k in ("friction=0.01", "pivot_friction=0.1", "pivot_radius=4",
                                                    "slip_friction=0.1", "roller_inertia=4e-4")]
    run = CliRunner().invoke(cli, ["solve", "ohc-finger-follower", "--csv", str(out), *sets])
    assert run.exit_code == 0, run.output
    assert "roller slip:" in run.output and "lever pivot friction: max pivot force" in run.output
    header = out.read_text().splitlines()[0]
    for column in ("cam_slip_speed (mm/s)", "cam_slip_power (N*mm/s)", "cam_pivot_force (N)",
                   "cam_pivot_torque (N*mm)", "cam_pivot_power (N*mm/s)"):
        assert column in header
