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

Friction at the cam-follower contact (``[follower] friction = μ``, default 0;
the laws themselves are :mod:`vtool.solvers.model.friction`):

* flat face: sliding, F_t = μ F_n (Coulomb), or with ``friction_law =
  "stribeck"`` F_t = μ(v_s) F_n with μ(v) = μ_c + (μ_s - μ_c) exp(-(v/v_S)²) +
  k_v v (μ_c = ``friction``). The face slides over the cam at v_s = ω (r_b + L)
  (the follower translates, the cam surface moves at ω times the tangent arm),
  so the friction power is F_t v_s = ω F_t (r_b + L): the friction's share of
  the drive torque dissipates exactly its power. There is no regularisation:
  v_s never vanishes (r_b + L > 0).
* roller: rolling; μ is the rolling traction coefficient, the drag of the
  roller's bearing referred to its rim (μ_pin r_pin / r_roller): F_t = μ F_n at
  the rim, power ω F_t times the tangent arm. With ``slip_friction = μ_slip``
  and ``roller_inertia = J`` the roller's slip is evaluated
  (:func:`vtool.solvers.model.friction.roller_slip`): the roller turns with the
  cam surface (rolling speed u = ω x the contact's entraining speed per radian)
  until the traction that needs, μ F_n + J (du/dt) / r², exceeds μ_slip F_n;
  it then slips (traction μ_slip F_n, its own spin from J dω/dt = r F_t - T_b)
  until it has caught up. Columns ``cam_slip_speed`` (u - r ω) and
  ``cam_slip_power``; the traction at the rim is then the friction force.
  Time is cam angle over ω (a run at constant speed).

Valve guide (``[follower] guide_friction = F_g``, a force, with
``guide_velocity = v_r``, default 1 mm/s): Coulomb friction on the stem,
regularised as F = F_g tanh(v / v_r) (v the valve's velocity; F_g the stem's
side load times the guide's coefficient, taken as constant over the cycle),
power F v >= 0; with the Stribeck law F = [F_g + (F_s - F_g) exp(-(v/v_S)²)]
tanh(v / v_r), F_s = ``guide_static_friction`` (no viscous term: k_v is a
coefficient per speed of the cam contact).

Rocker or finger pivot (``pivot_friction = μ_p``, ``pivot_radius = r_p``,
``pivot_velocity = Ω_r``, default 1 rad/s): the lever is taken massless and
quasi-static, so the valve pad's force P balances the cam's moment about the
pivot (P b cos φ = F_n (Q × n), Q the roller centre, b the valve arm) and the
pivot carries the rest, F_p = |F_n n + P_vec|. The friction torque is
μ_p F_p r_p tanh(Ω / Ω_r) against the lever's angular velocity Ω = ω dφ/dθ,
power T Ω: columns ``cam_pivot_force``, ``cam_pivot_torque``,
``cam_pivot_power``. At the base circle of a finger with the roller on the
pivot-pad line and the cam above it, F_p = F_n (1 - a/b) (a the roller arm).

The friction forces are computed after the run: they do
not act back on the model's dynamics (the model's coordinates move along
the follower's line of action, on which the tangential force does no work
for a translating follower; a finger's pivot would take a small moment from
it, neglected). Only loaded rows (F_n > 0) carry friction.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from vtool.solvers.model import friction as friction_laws
from vtool.solvers.model.cam import derivatives, lift_series
from vtool.solvers.model.camshape import FingerGeometry, contact, finger_angle
from vtool.solvers.model.friction import COULOMB, STRIBECK, FrictionLaws
from vtool.solvers.model.spec import FLAT, MechanismSpec

#: CSV/summary names of the row quantities and their unit kinds (the last five: only where evaluated,
#: :func:`row_names`)
ROW_UNITS = {"torque": "torque", "friction_force": "force", "friction_power": "power",
             "slip_speed": "speed", "slip_power": "power",
             "pivot_force": "force", "pivot_torque": "torque", "pivot_power": "power"}
SLIP = ("slip_speed", "slip_power")
PIVOT = ("pivot_force", "pivot_torque", "pivot_power")


@dataclass(frozen=True)
class TorqueRows:
    """Per output row: the cam's normal force, drive torque and the contact's friction (module doc)."""

    cam_angle_deg: np.ndarray
    normal_force: np.ndarray
    torque: np.ndarray  # force x length
    friction_force: np.ndarray
    friction_power: np.ndarray  # force x length / s
    slip_speed: np.ndarray | None = None  # a roller's u - r ω (with slip_friction)
    slip_power: np.ndarray | None = None
    pivot_force: np.ndarray | None = None  # a lever's pivot reaction (with pivot_friction)
    pivot_torque: np.ndarray | None = None
    pivot_power: np.ndarray | None = None


def _laws(spec: MechanismSpec) -> FrictionLaws:
    laws = None if spec.follower is None else spec.follower.laws
    return laws if laws is not None else FrictionLaws()


def row_names(spec: MechanismSpec) -> tuple[str, ...]:
    """The row quantities a run of ``spec`` reports (the slip's and the pivot's where their laws are given)."""
    laws = _laws(spec)
    return (("torque", "friction_force", "friction_power") + (SLIP if laws.slip > 0.0 else ())
            + (PIVOT if laws.pivot_radius > 0.0 else ()))


def whole_run(spec: MechanismSpec) -> bool:
    """True when the rows depend on the ones before (the roller's slip): compute over the whole run at once."""
    return _laws(spec).slip > 0.0


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
    """The drive torque and friction at rows of cam angle (deg) and model cam-contact force (module doc).

    With a roller's slip law the rows must be a whole run in order (:func:`whole_run`)."""
    angles = np.asarray(cam_angle_deg, dtype=float)
    factor, arm, tangent = arms(spec, angles)
    normal = np.asarray(model_force, dtype=float) * factor
    load = np.maximum(normal, 0.0)
    follower, laws, omega = spec.follower, _laws(spec), spec.run.omega
    mu = 0.0 if follower is None else follower.friction
    surface = omega * np.abs(tangent)  # a flat face's sliding speed; the cam surface's speed along the tangent
    extra: dict[str, np.ndarray] = {}
    if follower is not None and follower.kind == FLAT and laws.sliding == STRIBECK:
        friction = friction_laws.stribeck(surface, load, mu, laws.static, laws.stribeck_velocity, laws.viscous)[0]
    else:
        friction = mu * load
    if follower is not None and laws.slip > 0.0:
        rolling = omega * contact(follower, spec.lift_law, np.radians(angles)).entraining_per_omega
        r = follower.roller_radius
        slip = friction_laws.roller_slip(np.radians(angles) / omega, rolling, load, r, laws.roller_inertia,
                                         mu * load * r, laws.slip)
        friction = np.where(load > 0.0, slip.traction, 0.0)
        extra |= {"slip_speed": slip.slip_speed, "slip_power": slip.slip_power}
    if follower is not None and laws.pivot_radius > 0.0:
        extra |= pivot_rows(spec, angles, normal)
    torque = normal * arm + friction * np.abs(tangent)
    return TorqueRows(angles, normal, torque, friction, friction * surface, **extra)


def pivot_rows(spec: MechanismSpec, cam_angle_deg: np.ndarray, normal: np.ndarray) -> dict[str, np.ndarray]:
    """A lever's pivot force, friction torque and power at rows of cam angle (deg) and normal force (module
    doc: the lever massless, its valve force balancing the cam's moment about the pivot)."""
    follower, laws = spec.follower, _laws(spec)
    assert follower is not None and follower.finger is not None
    theta = np.radians(np.asarray(cam_angle_deg, dtype=float))
    c = contact(follower, spec.lift_law, theta)
    assert c.normal is not None and c.lever_angle is not None
    phi, n = c.lever_angle, c.normal
    Q = FingerGeometry.of(follower).roller(phi)
    load = np.maximum(normal, 0.0)
    valve = -load * (Q[0] * n[1] - Q[1] * n[0]) / (follower.finger.valve_arm * np.cos(phi))  # on the pad, along y
    force = np.hypot(load * n[0], load * n[1] + valve)
    h = 1e-5  # rad: the lever's angular velocity Ω = ω dφ/dθ by a central difference of the kinematics
    rate = (finger_angle(follower, spec.lift_law, theta + h) - finger_angle(follower, spec.lift_law, theta - h)) / (2 * h)
    torque, power = friction_laws.pivot(spec.run.omega * rate, force, laws.pivot, laws.pivot_radius,
                                        laws.pivot_velocity)
    return {"pivot_force": force, "pivot_torque": torque, "pivot_power": power}


def guide_rows(spec: MechanismSpec, valve_velocity: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The valve guide's friction force and power at rows of valve velocity (module doc)."""
    follower = spec.follower
    v = np.asarray(valve_velocity, dtype=float)
    if follower is None or follower.guide_friction == 0.0:
        return np.zeros_like(v), np.zeros_like(v)
    laws = _laws(spec)
    if laws.sliding == STRIBECK:  # the law's coefficients as forces: on a unit load
        return friction_laws.stribeck(v, np.ones_like(v), follower.guide_friction, laws.guide_static,
                                      laws.stribeck_velocity, 0.0, follower.guide_velocity)
    return friction_laws.coulomb(v, np.ones_like(v), follower.guide_friction, follower.guide_velocity)


def row_unit(spec: MechanismSpec, name: str) -> str:
    units = spec.unit_system
    return {"torque": f"{units.force}*{units.length}", "force": units.force,
            "power": f"{units.force}*{units.length}/s", "speed": f"{units.length}/s"}[ROW_UNITS[name]]


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
              0.0 if spec.follower is None else spec.follower.friction, "friction_law": _laws(spec).sliding}
    if len(angle) < 2:
        return result
    span = angle[-1] - angle[0]
    result.update(
        mean_torque=float(np.trapezoid(torque, angle) / span),
        max_torque=float(torque.max()), min_torque=float(torque.min()),
        peak_to_peak_torque=float(torque.max() - torque.min()),
        mean_friction_power=float(np.trapezoid(rows.friction_power[window], angle) / span),
        max_friction_force=float(rows.friction_force[window].max()))
    if rows.slip_speed is not None and rows.slip_power is not None:
        result.update(speed_unit=row_unit(spec, "slip_speed"),
                      max_slip_speed=float(np.abs(rows.slip_speed[window]).max()),
                      mean_slip_power=float(np.trapezoid(rows.slip_power[window], angle) / span),
                      slipping_deg=float(np.sum(np.diff(angle)[(np.abs(rows.slip_speed[window][1:]) > 0.0)
                                                               & (rows.normal_force[window][1:] > 0.0)])))
    if rows.pivot_force is not None and rows.pivot_power is not None:
        result.update(max_pivot_force=float(rows.pivot_force[window].max()),
                      mean_pivot_power=float(np.trapezoid(rows.pivot_power[window], angle) / span))
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
        law = "" if s.get("friction_law", COULOMB) == COULOMB else f"{s['friction_law']}, "
        lines.append(f"cam-follower friction ({law}mu {s['friction_coefficient']:g}): mean power "
                     f"{s['mean_friction_power']:.5g} {s['power_unit']}, max force {s['max_friction_force']:.5g} {s['force_unit']}")
    if "max_slip_speed" in s:
        lines.append(f"roller slip: {s['slipping_deg']:.4g} deg of the cycle slipping under load, max slip speed "
                     f"{s['max_slip_speed']:.5g} {s['speed_unit']}, mean slip power {s['mean_slip_power']:.5g} "
                     f"{s['power_unit']}")
    if "max_pivot_force" in s:
        lines.append(f"lever pivot friction: max pivot force {s['max_pivot_force']:.5g} {s['force_unit']}, mean "
                     f"power {s['mean_pivot_power']:.5g} {s['power_unit']}")
    if "mean_guide_friction_power" in s:
        lines.append(f"valve guide friction: mean power {s['mean_guide_friction_power']:.5g} {s['power_unit']}")
    return lines
