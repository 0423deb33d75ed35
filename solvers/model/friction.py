"""Friction laws of the valve gear's contacts (issue 41): plain NumPy functions of velocity and load.

Each law gives the friction force (or torque) opposing a relative velocity,
and the power it dissipates (always >= 0), at arrays of rows. Units are the
caller's (force, length, time consistent: a preset's unit system, or SI);
velocities are signed, loads >= 0 (a negative load is taken as 0: a contact
that has opened carries no friction). The post-processing outputs
(:mod:`vtool.solvers.studies.torque`) and the back end that makes friction
act on the motion both call these, so the law is written once.

Laws:

* :func:`coulomb`: F = μ N tanh(v / v_r). Coulomb's law regularised with a
  stated velocity v_r (below |v| ~ v_r the force ramps through zero instead
  of jumping; v_r = 0 is the sharp law, F = μ N sign v).
* :func:`stribeck`: the coefficient falls from its static value μ_s to the
  Coulomb value μ_c as the sliding speed rises past the Stribeck speed v_S,
  then rises with a viscous slope k_v (s/length: coefficient per unit speed)::

      μ(v) = μ_c + (μ_s - μ_c) exp(-(|v| / v_S)²) + k_v |v|
      F = μ(v) N tanh(v / v_r)

  (the Gaussian decay of Armstrong-Hélouvry's form; with μ_s = μ_c and
  k_v = 0 it is :func:`coulomb`).
* :func:`pivot`: a rocker's or finger's pivot, a pin (or ball) of radius r_p
  carrying the reaction F_p with coefficient μ: the friction torque is
  T = μ F_p r_p tanh(Ω / Ω_r) against the lever's angular velocity Ω, power
  T Ω.
* :func:`roller_slip`: a roller driven by traction at its rim. It turns with
  the cam (rim speed = the surface's rolling speed u, no slip) while the
  traction that demands, |F_d| = |T_b + J (du/dt) / r| / r (T_b the bearing's
  drag torque, J the roller's moment of inertia about its pin, r its radius),
  is at most μ_slip N. Above that the roller slips: the traction is
  μ_slip N in the direction of the slip, the roller's angular velocity ω
  follows J dω/dt = r F_t - T_b sign ω, and the slip speed is u - r ω, until
  the slip speed changes sign (the roller has caught up: it sticks again).
  Power lost to slip: F_t |u - r ω|. Integrated along the rows (explicit,
  first order in the row spacing; the stick test at each row makes the
  return to rolling exact where the traction can hold it).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


def _direction(v: np.ndarray, v_reg: float) -> np.ndarray:
    """tanh(v / v_r), or sign v for v_r = 0 (the sharp law)."""
    v = np.asarray(v, dtype=float)
    return np.sign(v) if v_reg == 0.0 else np.tanh(v / v_reg)


def _load(normal: np.ndarray) -> np.ndarray:
    return np.maximum(np.asarray(normal, dtype=float), 0.0)


def coulomb(v: np.ndarray, normal: np.ndarray, mu: float, v_reg: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """(force, power) of regularised Coulomb friction, F = μ N tanh(v / v_r) (module doc)."""
    force = mu * _load(normal) * _direction(v, v_reg)
    return force, force * np.asarray(v, dtype=float)


def stribeck_coefficient(v: np.ndarray, mu_coulomb: float, mu_static: float, v_stribeck: float,
                         viscous: float = 0.0) -> np.ndarray:
    """μ(v) = μ_c + (μ_s - μ_c) exp(-(|v| / v_S)²) + k_v |v| (module doc)."""
    speed = np.abs(np.asarray(v, dtype=float))
    return mu_coulomb + (mu_static - mu_coulomb) * np.exp(-(speed / v_stribeck) ** 2) + viscous * speed


def stribeck(v: np.ndarray, normal: np.ndarray, mu_coulomb: float, mu_static: float, v_stribeck: float,
             viscous: float = 0.0, v_reg: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """(force, power) of the Stribeck law F = μ(v) N tanh(v / v_r) (module doc)."""
    force = stribeck_coefficient(v, mu_coulomb, mu_static, v_stribeck, viscous) * _load(normal) * _direction(v, v_reg)
    return force, force * np.asarray(v, dtype=float)


def pivot(angular_velocity: np.ndarray, pivot_force: np.ndarray, mu: float, pin_radius: float,
          omega_reg: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """(torque, power) of a pivot's friction, T = μ F_p r_p tanh(Ω / Ω_r) (module doc)."""
    torque = mu * _load(pivot_force) * pin_radius * _direction(angular_velocity, omega_reg)
    return torque, torque * np.asarray(angular_velocity, dtype=float)


@dataclass(frozen=True)
class RollerSlip:
    """:func:`roller_slip` at each row."""

    roller_speed: np.ndarray  # the roller's rim speed r ω (length/s)
    traction: np.ndarray  # the force the cam puts on the roller's rim, along the rolling direction
    slip_speed: np.ndarray  # u - r ω
    slip_power: np.ndarray  # |traction (u - r ω)|
    slipping: np.ndarray  # bool


def roller_slip(t: np.ndarray, rolling_speed: np.ndarray, normal: np.ndarray, radius: float, inertia: float,
                bearing_torque: np.ndarray, mu_slip: float) -> RollerSlip:
    """The roller's stick-slip along rows of time ``t`` (module doc).

    ``rolling_speed`` u: the speed at which the cam surface passes the
    contact (the rim speed of a roller that rolls); ``bearing_torque`` T_b:
    the drag torque of the roller's bearing (>= 0, it opposes the roller's
    turning); ``inertia`` J about the pin. The first row rolls if the
    traction can hold it (the roller starts at the surface's speed).
    """
    t = np.asarray(t, dtype=float)
    u = np.asarray(rolling_speed, dtype=float)
    limit = mu_slip * _load(normal)
    drag = np.abs(np.broadcast_to(np.asarray(bearing_torque, dtype=float), t.shape))
    n = len(t)
    du = np.gradient(u, t) if n > 1 else np.zeros(n)
    speed = np.empty(n)
    traction = np.empty(n)
    slipping = np.zeros(n, dtype=bool)
    rim = u[0] if n else 0.0
    for i in range(n):
        if i > 0:
            dt = t[i] - t[i - 1]
            if slipping[i - 1]:  # J dω/dt = r F_t - T_b sign ω, as rim speed: d(rω)/dt = r (r F_t - T_b sign ω) / J
                rim = rim + dt * radius * (radius * traction[i - 1] - drag[i - 1] * np.sign(rim)) / inertia
            else:
                rim = u[i - 1] + dt * du[i - 1]
            before = u[i - 1] - speed[i - 1]  # the slip speed at the last row (0 where a slip begins)
            crossed = slipping[i - 1] and before != 0.0 and (u[i] - rim) * before <= 0.0
            if crossed or not slipping[i - 1]:
                rim = u[i]  # caught up (or rolling): try to roll at this row
        sign = np.sign(rim) if rim != 0.0 else np.sign(u[i])
        demand = (drag[i] * sign + inertia * du[i] / radius) / radius
        if rim == u[i] and abs(demand) <= limit[i]:
            speed[i], traction[i] = u[i], demand
        else:
            slipping[i] = True
            speed[i] = rim
            slip = u[i] - rim
            traction[i] = limit[i] * (np.sign(slip) if slip != 0.0 else np.sign(demand))
    slip_speed = u - speed
    return RollerSlip(speed, traction, slip_speed, np.abs(traction * slip_speed), slipping)


COULOMB = "coulomb"
STRIBECK = "stribeck"
SLIDING_LAWS = (COULOMB, STRIBECK)


@dataclass(frozen=True)
class FrictionLaws:
    """A follower's friction laws beyond its coefficients ``friction`` and ``guide_friction``
    (:class:`vtool.solvers.model.spec.FollowerSpec`), in the preset's units.

    ``sliding``: the law of the sliding contacts (a flat face on the cam, the valve
    guide): ``coulomb`` or ``stribeck`` (then ``static`` μ_s of the cam contact,
    ``guide_static`` the guide's force at rest, ``stribeck_velocity`` v_S,
    ``viscous`` k_v in time/length). ``pivot``/``pivot_radius``/``pivot_velocity``:
    a finger's or rocker's pivot (μ, r_p, Ω_r in rad/s). ``slip``/``roller_inertia``:
    a roller's slip law (μ_slip, J about the pin in mass × length²); 0: not evaluated.
    """

    sliding: str = COULOMB
    static: float = 0.0
    guide_static: float = 0.0
    stribeck_velocity: float = 0.0
    viscous: float = 0.0
    pivot: float = 0.0
    pivot_radius: float = 0.0
    pivot_velocity: float = 1.0
    slip: float = 0.0
    roller_inertia: float = 0.0
