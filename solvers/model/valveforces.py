"""Forces on the valve that act on the motion: guide friction (Stribeck) and the gas force on its head.

A nonlinear element (:mod:`vtool.solvers.model.nonlinear`) without states, on
one coordinate (the valve's, default the seat clearance's ahead end), in the
model's units; ``[valve_forces]`` in a preset (:mod:`vtool.presets.valveforces`).

* Guide friction, opposing the valve's velocity v (the law stated):

      F_f(v) = [F_c + (F_s - F_c) exp(-(v/v_s)²)] tanh(v/v_r) + c_v v

  F_c the Coulomb force (``guide_friction``), F_s the static peak
  (``static_friction``, default F_c: no Stribeck dip), v_s the Stribeck
  velocity, v_r the regularisation velocity of the sign (``guide_velocity``),
  c_v the viscous coefficient. F_s = F_c, c_v = 0 is the post-processed
  ``[follower] guide_friction`` law, F_c tanh(v/v_r), now acting.
* Gas force: a cylinder pressure p(φ) against crank angle (a table over one
  720-degree cycle, linear between its points, periodic), φ = 2 θ + φ₀ with
  θ the cam angle and φ₀ the crank angle at cam angle zero, on the head's
  area π D²/4. ``seat_side = "cylinder"`` (a poppet valve: the head in the
  cylinder, the pressure presses it onto its seat) pushes towards closing,
  ``"port"`` the other way; closing is the seat clearance's closing
  direction (the valve coordinate decreasing towards the seat).

While the valve is seated the gas force goes into the seat's contact force
(the back end's rigid-contact share).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from vtool.solvers.model import friction
from vtool.solvers.model.nonlinear import NonlinearElement

SEAT_SIDES = ("cylinder", "port")
LAWS = ("tanh", "stribeck")


@dataclass(frozen=True)
class ValveForces:
    """The valve's friction and gas data (model units; module doc)."""

    coordinate: int | None = None  # 1-based, the valve coordinate the forces act on (None: the seat's valve)
    guide_friction: float = 0.0  # F_c
    guide_velocity: float = 1.0  # v_r
    static_friction: float | None = None  # F_s (None: F_c)
    stribeck_velocity: float = 1.0  # v_s
    viscous: float = 0.0  # c_v
    gas_angles: tuple[float, ...] = ()  # crank deg, increasing within one 720-degree cycle
    gas_pressures: tuple[float, ...] = ()  # gauge, the model's pressure unit
    head_diameter: float = 0.0
    seat_side: str = "cylinder"
    gas_phase: float = 0.0  # crank deg at cam angle zero
    closing: float = -1.0  # the sign of the valve coordinate's motion towards its seat
    field: str = "valve_forces"

    @property
    def active(self) -> bool:
        return bool(self.guide_friction or self.static_friction or self.viscous or self.gas_angles)

    @property
    def law(self) -> str:
        return "stribeck" if self.static_friction not in (None, self.guide_friction) else "tanh"


def friction_force(vf: ValveForces, v: float | np.ndarray) -> float | np.ndarray:
    """F_f(v) (module doc): positive along v; the force on the valve is -F_f. The dry part is the Stribeck
    law of :mod:`vtool.solvers.model.friction` on a unit load (its coefficients are forces here)."""
    velocity = np.asarray(v, dtype=float)
    if vf.static_friction is None:  # no Stribeck dip: the static peak is the Coulomb level
        dry, _ = friction.coulomb(velocity, np.ones_like(velocity), vf.guide_friction, vf.guide_velocity)
    else:
        dry, _ = friction.stribeck(velocity, np.ones_like(velocity), vf.guide_friction, vf.static_friction,
                                   float(vf.stribeck_velocity), 0.0, vf.guide_velocity)
    out = dry + vf.viscous * velocity
    return float(out) if np.ndim(v) == 0 else out


def cylinder_pressure(vf: ValveForces, cam_deg: float | np.ndarray) -> float | np.ndarray:
    """p at cam angle θ (deg): the table at crank angle 2θ + φ₀ (mod 720), periodic."""
    if not vf.gas_angles:
        return np.zeros(np.shape(cam_deg)) if np.ndim(cam_deg) else 0.0
    crank = np.mod(2.0 * np.asarray(cam_deg) + vf.gas_phase, 720.0)
    return np.interp(crank, vf.gas_angles, vf.gas_pressures, period=720.0)


def gas_force(vf: ValveForces, cam_deg: float | np.ndarray) -> float | np.ndarray:
    """The gas force on the valve coordinate (positive along it)."""
    area = math.pi * vf.head_diameter**2 / 4.0
    towards = vf.closing if vf.seat_side == "cylinder" else -vf.closing
    return towards * area * cylinder_pressure(vf, cam_deg)


def valve_coordinate(spec) -> int:  # noqa: ANN001 (a MechanismSpec)
    """The coordinate the valve forces act on: the given one, else the seat clearance's ahead end."""
    if spec.valve_forces.coordinate is not None:
        return spec.valve_forces.coordinate
    seat = spec.seat.coordinate if spec.seat is not None else None
    return next(c.ahead for c in spec.clearances if c.behind == seat)


class ValveForceElement(NonlinearElement):
    """The valve forces as a nonlinear element (no states)."""

    key = "valve_forces"

    def __init__(self, spec) -> None:  # noqa: ANN001 (a MechanismSpec: spec.py imports this module)
        self.vf: ValveForces = spec.valve_forces
        self.field = self.vf.field
        self.index = valve_coordinate(spec) - 1
        self.degrees_per_second = spec.run.omega * 180.0 / math.pi
        self.units = spec.unit_system

    def initial(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        return np.zeros(0)

    def on_valve(self, t: float | np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(friction, gas) forces on the valve coordinate at t with velocities v."""
        speed = v[self.index]
        return (np.asarray(-friction_force(self.vf, speed)),
                np.asarray(gas_force(self.vf, np.asarray(t) * self.degrees_per_second)))

    def evaluate(self, t, q: np.ndarray, v: np.ndarray, s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:  # noqa: ANN001
        friction, gas = self.on_valve(t, v)
        force = np.zeros(np.shape(q))
        force[self.index] = friction + gas
        return force, np.zeros(np.shape(s))

    def columns(self, t: np.ndarray, q: np.ndarray, v: np.ndarray, s: np.ndarray) -> list[tuple[str, str, np.ndarray]]:
        units = self.units
        friction, gas = self.on_valve(t, v)
        return [("valve_friction_force", units.force, friction),
                ("valve_friction_power", f"{units.force}*{units.length}/{units.time}", -friction * v[self.index]),
                ("valve_gas_force", units.force, np.broadcast_to(gas, np.shape(t)).astype(float))]

    def summary(self, trace, s: np.ndarray) -> dict:  # noqa: ANN001 (a Trace)
        n = trace.spec.n_coordinates
        rows = self.columns(trace.time, trace.q[:, :n].T, trace.qd[:, :n].T, s)
        values = {name: data for name, _, data in rows}
        time = trace.time
        span = float(time[-1] - time[0]) if len(time) > 1 else 0.0
        mean = float(np.trapezoid(values["valve_friction_power"], time) / span) if span > 0 else 0.0
        units = self.units
        return {"law": self.vf.law, "mean_friction_power": mean,
                "power_unit": f"{units.force}*{units.length}/{units.time}",
                "friction_force_max": float(np.max(np.abs(values["valve_friction_force"]))),
                "gas_force_max": float(np.max(np.abs(values["valve_gas_force"]))), "force_unit": units.force}

    def summary_text(self, entry: dict) -> list[str]:
        return [f"valve forces on the motion ({entry['law']} guide friction): largest friction "
                f"{entry['friction_force_max']:.4g} {entry['force_unit']}, mean friction power "
                f"{entry['mean_friction_power']:.4g} {entry['power_unit']}; largest gas force "
                f"{entry['gas_force_max']:.4g} {entry['force_unit']}"]
