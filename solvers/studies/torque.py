"""The cam's drive torque and the cam-follower friction at a run's output rows.

The follower pushes on the cam with the normal force F_n along the cam's
outward normal n at the contact point x (camshaft axis C). The torque that
drives the camshaft against it is the moment of that force and of the
friction force F_t along the tangent (:class:`vtool.solvers.model.camshape.Contact`):

    T = F_n (x - C) × n  +  F_t (x - C)·n        (the arms ``torque_arm``, ``tangent_arm``)

For every follower the first arm times F_n is F_model d(model lift)/dθ
(virtual work: the cam's power T ω is the power the cam contact puts into
the model), which the tests check at every row; a flat face's arm is L'
itself (the contact's offset from the axis along the face), a roller's
R sin α. A preset without a [follower] has the model's cam alone: T = F dL/dθ.

Friction at the cam-follower contact (``[follower] friction = μ``, default 0):

* flat face: Coulomb sliding, F_t = μ F_n. The face slides over the cam at
  v_s = ω (r_b + L) (the follower translates, the cam surface moves at ω
  times the tangent arm), so the friction power is μ F_n v_s = ω F_t (r_b + L):
  the friction's share of the drive torque dissipates exactly its power.
  There is no regularisation: v_s never vanishes (r_b + L > 0).
* roller: rolling without slip; μ is the rolling traction coefficient, the
  drag of the roller's bearing referred to its rim (μ_pin r_pin / r_roller,
  the roller's own inertia neglected): F_t = μ F_n at the rim, power ω F_t
  times the tangent arm, which the roller bearing dissipates.

Valve guide (``[follower] guide_friction = F_g``, a force, with
``guide_velocity = v_r``, default 1 mm/s): Coulomb friction on the stem,
regularised as F = F_g tanh(v / v_r) (v the valve's velocity; F_g the stem's
side load times the guide's coefficient, taken as constant over the cycle),
power F v >= 0. The rocker or finger pivot's friction is not modelled.

The friction forces are computed after the run: it does
not act back on the model's dynamics (the model's coordinates move along
the follower's line of action, on which the tangential force does no work
for a translating follower; a finger's pivot would take a small moment from
it, neglected). Only loaded rows (F_n > 0) carry friction.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from vtool.solvers.model.cam import derivatives, lift_series
from vtool.solvers.model.camshape import contact
from vtool.solvers.model.spec import MechanismSpec

#: CSV/summary names of the row quantities and their unit kinds
ROW_UNITS = {"torque": "torque", "friction_force": "force", "friction_power": "power"}


@dataclass(frozen=True)
class TorqueRows:
    """Per output row: the cam's normal force, drive torque and the contact's friction (module doc)."""

    cam_angle_deg: np.ndarray
    normal_force: np.ndarray
    torque: np.ndarray  # force x length
    friction_force: np.ndarray
    friction_power: np.ndarray  # force x length / s


def arms(spec: MechanismSpec, cam_angle_deg: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(normal force per unit model force, normal arm, tangent arm) at cam angles (deg)."""
    theta = np.radians(np.asarray(cam_angle_deg, dtype=float))
    if spec.follower is None:
        dL = derivatives(*lift_series(spec.cam), theta)[1]
        ones = np.ones_like(theta)
        return ones, dL, np.zeros_like(theta)
    c = contact(spec.follower, spec.lift_law, theta)
    return c.force_factor, c.torque_arm, c.tangent_arm


def torque_rows(spec: MechanismSpec, cam_angle_deg: np.ndarray, model_force: np.ndarray) -> TorqueRows:
    """The drive torque and friction at rows of cam angle (deg) and model cam-contact force (module doc)."""
    angles = np.asarray(cam_angle_deg, dtype=float)
    factor, arm, tangent = arms(spec, angles)
    normal = np.asarray(model_force, dtype=float) * factor
    mu = 0.0 if spec.follower is None else spec.follower.friction
    friction = mu * np.maximum(normal, 0.0)
    torque = normal * arm + friction * np.abs(tangent)
    power = friction * np.abs(tangent) * spec.run.omega
    return TorqueRows(angles, normal, torque, friction, power)


def guide_rows(spec: MechanismSpec, valve_velocity: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The valve guide's friction force and power at rows of valve velocity (module doc)."""
    follower = spec.follower
    v = np.asarray(valve_velocity, dtype=float)
    if follower is None or follower.guide_friction == 0.0:
        return np.zeros_like(v), np.zeros_like(v)
    force = follower.guide_friction * np.tanh(v / follower.guide_velocity)
    return force, force * v


def row_unit(spec: MechanismSpec, name: str) -> str:
    units = spec.unit_system
    return {"torque": f"{units.force}*{units.length}", "force": units.force,
            "power": f"{units.force}*{units.length}/s"}[ROW_UNITS[name]]


def last_revolution(cam_angle_deg: np.ndarray) -> tuple[float, int] | None:
    """(start deg, 1): the rows' last whole cam revolution (from a multiple of 360 deg), or None if none."""
    if len(cam_angle_deg) < 2:
        return None
    end = math.floor(float(cam_angle_deg[-1]) / 360.0 + 1e-9) * 360.0
    return (end - 360.0, 1) if end - 360.0 >= float(cam_angle_deg[0]) - 1e-9 else None


def torque_summary(spec: MechanismSpec, rows: TorqueRows, start: float, cycles: int) -> dict:
    """Mean, extremes, peak-to-peak and friction power of the drive torque over whole cycles from ``start``
    (a run's summary: its last whole revolution, :func:`last_revolution`)."""
    window = (rows.cam_angle_deg >= start - 1e-9) & (rows.cam_angle_deg <= start + 360.0 * cycles + 1e-9)
    angle = rows.cam_angle_deg[window]
    torque = rows.torque[window]
    result = {"torque_unit": row_unit(spec, "torque"), "power_unit": row_unit(spec, "friction_power"),
              "force_unit": spec.unit_system.force,
              "start_deg": start, "cycles": cycles, "friction_coefficient":
              0.0 if spec.follower is None else spec.follower.friction}
    if len(angle) < 2:
        return result
    span = angle[-1] - angle[0]
    result.update(
        mean_torque=float(np.trapezoid(torque, angle) / span),
        max_torque=float(torque.max()), min_torque=float(torque.min()),
        peak_to_peak_torque=float(torque.max() - torque.min()),
        mean_friction_power=float(np.trapezoid(rows.friction_power[window], angle) / span),
        max_friction_force=float(rows.friction_force[window].max()))
    return result


def torque_text(s: dict) -> list[str]:
    """Summary lines of :func:`torque_summary`'s dict."""
    if "mean_torque" not in s:
        return []
    u = s["torque_unit"]
    line = (f"cam drive torque over {s['cycles']} cycle{'s' if s['cycles'] > 1 else ''}: mean {s['mean_torque']:.5g} {u}, "
            f"{s['min_torque']:.5g} .. {s['max_torque']:.5g} {u} (peak-to-peak {s['peak_to_peak_torque']:.5g} {u})")
    lines = [line]
    if s["friction_coefficient"] > 0.0:
        lines.append(f"cam-follower friction (mu {s['friction_coefficient']:g}): mean power "
                     f"{s['mean_friction_power']:.5g} {s['power_unit']}, max force {s['max_friction_force']:.5g} {s['force_unit']}")
    if "mean_guide_friction_power" in s:
        lines.append(f"valve guide friction: mean power {s['mean_guide_friction_power']:.5g} {s['power_unit']}")
    return lines
