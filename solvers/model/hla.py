"""Hydraulic lash adjuster (HLA): plunger, high-pressure chamber, ball check valve and leakage gap.

SI units throughout (m, N, Pa, kg, s). The plunger (mass m, area A = π d²/4)
slides in the body; x is its extension out of the body (x grows as the
adjuster lengthens). Its plunger spring pushes it out with
F_s = F_s0 - k_s x. The chamber under it holds V = V0 + A x of oil at the
gauge pressure p. States: x, ẋ, p.

    m ẍ = p A + F_s(x) - F(t) - c ẋ                 (F: the load of the finger on the plunger)
    ṗ  = K(p) / V · (Q_check - Q_leak - A ẋ)

* Bulk modulus K(p): the oil's own K_oil(p) (a table against gauge
  pressure, linear interpolation, constant beyond its ends) with entrained
  air of volume fraction ε₀ at atmospheric pressure p_a, compressed
  isothermally (p_abs ε V = const) and not dissolving:
  ε(p) = ε₀ (p_a/p_abs) / (1 - ε₀ + ε₀ p_a/p_abs), and
  1/K = (1 - ε)/K_oil + ε/p_abs (Wood's mixture rule, the air's isothermal
  bulk modulus p_abs).
* Ball check valve from the supply (gauge pressure p_s): it opens when the
  supply exceeds the chamber by the crack pressure Δp_c and passes
  Q_check = G (p_s - p - Δp_c) then (a linear conductance G, m³/(s·Pa),
  standing for the ball's lift-limited orifice; the ball's own dynamics and
  closing delay are not modelled); shut otherwise.
* Leakage through the plunger's annular gap (radial clearance h, length
  L, oil viscosity μ) to the supply side: Q_leak = π d h³ (p - p_s) / (12 μ L).

With the check shut and no leakage the chamber is a spring of stiffness
K A² / V (``closed_stiffness``); a steady load bleeds the plunger down at
ẋ = -Q_leak / A (``leak_down_rate``); :func:`pump_up` runs a load history
cycle after cycle and reports the plunger's drift per cycle.

The element runs alone (:func:`simulate`, scipy's LSODA) or in a valve
train's chain (:class:`HLAElement`, a :class:`~vtool.solvers.model.nonlinear.NonlinearElement`,
from a preset's ``[hla]`` or ``[train.hla]``): there it takes the place of a
bar member (the finger's pivot support). That member stays in the linear
model with the closed chamber's stiffness k₀ = K(p₀) A²/V₀ and the plunger's
mass (so the static start, the configurations and the back ends' linear
machinery are those of a stiff pivot), and the element adds the difference
between the adjuster's force and the member's: on the member's end b,
f = -σ F_hla + k₀ u (u the member's elongation in model units, σ = +1 when
a positive elongation shortens the adjuster, ``sense = "compression"``), and
the opposite on end a. The plunger's extension is x = -σ u, its mass the
member's. The chamber pressure p is the element's one state (in the model's
pressure unit); at the start it balances the member's static force,
p₀ = (σ k₀ u₀ - F_s(x₀)) / A, or the supply pressure where that is lower
(the check valve has filled the chamber: the plunger then pumps up).
Not modelled: cavitation (with no entrained air the gauge pressure may fall
below -1 atm while the plunger extends faster than the check valve fills it;
with air the mixture's bulk modulus falls towards zero as the absolute
pressure does, which holds it above vacuum), the ball's own dynamics, and
friction of the plunger in its bore beyond the viscous ``damping``.
"""

from __future__ import annotations

import bisect
import math
from collections.abc import Callable
from dataclasses import dataclass
from dataclasses import field as dataclass_field
from typing import Any

import numpy as np

from vtool.solvers.model.nonlinear import NonlinearElement

ATMOSPHERE = 101_325.0  # Pa


@dataclass(frozen=True)
class HLASpec:
    """An HLA's data (SI units; module doc)."""

    plunger_diameter: float  # m
    chamber_volume: float  # V0, m³ at x = 0
    plunger_mass: float  # kg
    spring_rate: float  # k_s, N/m
    spring_preload: float  # F_s0, N at x = 0
    gap: float  # h, radial clearance, m
    gap_length: float  # L, m
    viscosity: float  # μ, Pa·s
    supply_pressure: float  # p_s, gauge Pa
    check_conductance: float  # G, m³/(s·Pa)
    crack_pressure: float = 0.0  # Δp_c, Pa
    bulk_pressures: tuple[float, ...] = (0.0,)  # gauge Pa, increasing
    bulk_moduli: tuple[float, ...] = (1.6e9,)  # K_oil at those pressures, Pa
    air_fraction: float = 0.0  # ε₀ at atmospheric pressure
    damping: float = 0.0  # c, N·s/m (plunger in its bore)

    @property
    def area(self) -> float:
        return math.pi * self.plunger_diameter**2 / 4.0

    def volume(self, x: float | np.ndarray) -> float | np.ndarray:
        return self.chamber_volume + self.area * x


def bulk_modulus(spec: HLASpec, p: float | np.ndarray) -> float | np.ndarray:
    """K(p) of the oil with its entrained air (module doc)."""
    oil = np.interp(p, spec.bulk_pressures, spec.bulk_moduli)
    if spec.air_fraction == 0.0:
        return oil
    absolute = np.maximum(np.asarray(p, dtype=float) + ATMOSPHERE, 1.0)
    ratio = spec.air_fraction * ATMOSPHERE / absolute
    eps = ratio / (1.0 - spec.air_fraction + ratio)
    return 1.0 / ((1.0 - eps) / oil + eps / absolute)


def leakage(spec: HLASpec, p: float | np.ndarray) -> float | np.ndarray:
    """Q_leak = π d h³ (p - p_s) / (12 μ L), m³/s out of the chamber."""
    return math.pi * spec.plunger_diameter * spec.gap**3 * (p - spec.supply_pressure) / (
        12.0 * spec.viscosity * spec.gap_length)


def check_flow(spec: HLASpec, p: float | np.ndarray) -> float | np.ndarray:
    """Q_check = G (p_s - p - Δp_c) when positive, else 0 (the ball shut)."""
    return spec.check_conductance * np.maximum(spec.supply_pressure - p - spec.crack_pressure, 0.0)


def closed_stiffness(spec: HLASpec, p: float, x: float = 0.0) -> float:
    """K A² / V: the stiffness of the closed chamber (check shut, no leakage) at pressure p, extension x."""
    return float(bulk_modulus(spec, p)) * spec.area**2 / float(spec.volume(x))


def leak_down_rate(spec: HLASpec, load: float, x: float = 0.0) -> float:
    """ẋ (m/s, negative) of a plunger under a steady load F: p = (F - F_s(x)) / A, ẋ = -Q_leak(p) / A."""
    p = (load - (spec.spring_preload - spec.spring_rate * x)) / spec.area
    return -float(leakage(spec, p)) / spec.area


def rhs(spec: HLASpec, load: Callable[[float, float], float], closed: bool = False
        ) -> Callable[[float, np.ndarray], np.ndarray]:
    """d/dt (x, ẋ, p) under a load F(t, x) (``closed``: check shut and no leakage)."""
    A = spec.area

    def f(t: float, y: np.ndarray) -> np.ndarray:
        x, v, p = y
        force = p * A + spec.spring_preload - spec.spring_rate * x - load(t, x) - spec.damping * v
        flow = 0.0 if closed else float(check_flow(spec, p)) - float(leakage(spec, p))
        dp = float(bulk_modulus(spec, p)) / float(spec.volume(x)) * (flow - A * v)
        return np.array([v, force / spec.plunger_mass, dp])

    return f


def static_extension(spec: HLASpec, load: float, p0: float, x0: float = 0.0, steps: int = 2000) -> float:
    """The closed chamber's equilibrium extension under a static load: integrates dp = -K(p) A dx / V(x)
    (no flow) from (x0, p0) to the pressure balancing the load, p A + F_s(x) = F, by Newton's method."""
    from scipy.integrate import solve_ivp

    A = spec.area

    def pressure_at(x: float) -> float:
        if x == x0:
            return p0
        sol = solve_ivp(lambda s, p: -bulk_modulus(spec, p) * A / spec.volume(s), (x0, x), [p0],
                        rtol=1e-13, atol=1e-6)
        return float(sol.y[0, -1])

    x = x0
    for _ in range(50):
        residual = pressure_at(x) * A + spec.spring_preload - spec.spring_rate * x - load
        slope = -closed_stiffness(spec, pressure_at(x), x) - spec.spring_rate
        step = residual / slope
        x -= step
        if abs(step) < 1e-15:
            break
    return x


@dataclass(frozen=True)
class HLARun:
    """A run of the element: rows of time, extension, velocity and pressure, and the check's openings."""

    time: np.ndarray
    extension: np.ndarray
    velocity: np.ndarray
    pressure: np.ndarray
    check_open_times: np.ndarray  # times the check valve opened (s)


def simulate(spec: HLASpec, load: Callable[[float, float], float], duration: float, y0: tuple[float, float, float],
             rows: int = 2000, closed: bool = False, rtol: float = 1e-8) -> HLARun:
    """Integrate the element (scipy LSODA: the chamber is stiff) and sample ``rows`` rows."""
    from scipy.integrate import solve_ivp

    t = np.linspace(0.0, duration, rows)
    sol = solve_ivp(rhs(spec, load, closed), (0.0, duration), list(y0), method="LSODA", t_eval=t, rtol=rtol,
                    atol=[1e-12, 1e-9, 1e-3], max_step=duration / 200.0)
    if not sol.success:
        from vtool.errors import RunError

        raise RunError(f"hla: the integration stopped ({sol.message})")
    opening = spec.supply_pressure - sol.y[2] - spec.crack_pressure > 0.0
    starts = np.flatnonzero(opening[1:] & ~opening[:-1]) + 1
    return HLARun(sol.t, sol.y[0], sol.y[1], sol.y[2], sol.t[starts])


def pump_up(spec: HLASpec, load: Callable[[float, float], float], period: float, cycles: int,
            y0: tuple[float, float, float], rows_per_cycle: int = 400) -> tuple[HLARun, np.ndarray]:
    """Run ``cycles`` periods of a load history; the drift per cycle: the plunger's extension at each cycle's
    start minus the previous one's (m; positive: pump-up, the adjuster lengthens)."""
    run = simulate(spec, load, period * cycles, y0, rows=rows_per_cycle * cycles + 1)
    starts = np.interp(period * np.arange(cycles + 1), run.time, run.extension)
    return run, np.diff(starts)


# ----- the HLA in a valve train's chain -----

#: what a positive elongation of the member in the adjuster's place means for the adjuster
SENSES = {"compression": 1.0, "extension": -1.0}


@dataclass(frozen=True)
class HLAPlace:
    """An HLA in a valve train (``[hla]``): its data (SI) and the bar member it sits in (module doc)."""

    hla: HLASpec  # SI; plunger_mass unused here (the member's mass is the plunger's)
    member: str  # the bar member in the adjuster's place
    sense: str = "compression"  # see SENSES
    initial_pressure: float | None = None  # gauge Pa at the start (None: from the static load, module doc)
    field: str = "hla"  # the preset field
    #: the preset's keys as given (model units), for a saved copy
    given: tuple[tuple[str, Any], ...] = dataclass_field(default=(), compare=False)


class HLAElement(NonlinearElement):
    """The HLA acting in the chain (module doc)."""

    state_names = ("hla_pressure",)
    key = "hla"

    def __init__(self, spec) -> None:  # noqa: ANN001 (a MechanismSpec: spec.py imports this module)
        place: HLAPlace = spec.hla
        self.place = place
        self.field = place.field
        units = spec.unit_system
        self.units = units
        self.length_m = units.metres_per_length
        self.force_n = units.newtons_per_force
        self.pressure_pa = units.pascals_per_pressure
        self.state_units = (units.pressure,)
        member = next(m for m in spec.members if m.name == place.member)
        if member.element != "bar" or member.stiffness is None:
            raise ValueError(f"hla.member {place.member}: a bar member with a stiffness")
        self.stiffness = float(member.stiffness)  # k0, model units
        self.n = spec.n_coordinates
        self.ends = [(abs(c) - 1, 1.0 if c > 0 else -1.0) for c in member.coordinates]  # (index or -1, sign)
        self.sigma = SENSES[place.sense]
        self.area = place.hla.area
        spec_h = place.hla
        self.leak_conductance = math.pi * spec_h.plunger_diameter * spec_h.gap**3 / (12.0 * spec_h.viscosity
                                                                                    * spec_h.gap_length)

    # the member's elongation u = q_b - q_a (signed ends; a grounded end is 0)
    def elongation(self, q: np.ndarray) -> np.ndarray:
        (ia, sa), (ib, sb) = self.ends
        u = np.zeros(np.shape(q)[1:])
        if ib >= 0:
            u = u + sb * q[ib]
        if ia >= 0:
            u = u - sa * q[ia]
        return np.asarray(u)

    def extension(self, q: np.ndarray) -> np.ndarray:
        """The plunger's extension x (model length)."""
        return -self.sigma * self.elongation(q)

    def adjuster_force(self, q: np.ndarray, v: np.ndarray, p: np.ndarray) -> np.ndarray:
        """F_hla (N): p A + F_s(x) - c ẋ, pushing the plunger out."""
        spec = self.place.hla
        x = self.extension(q) * self.length_m
        xd = self.extension(v) * self.length_m
        return p * self.pressure_pa * spec.area + spec.spring_preload - spec.spring_rate * x - spec.damping * xd

    def initial(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        spec = self.place.hla
        if self.place.initial_pressure is not None:
            return np.array([self.place.initial_pressure / self.pressure_pa])
        u0 = float(self.elongation(q))
        load = self.sigma * self.stiffness * u0 * self.force_n  # N the member carries at the start
        x0 = -self.sigma * u0 * self.length_m
        balance = (load - (spec.spring_preload - spec.spring_rate * x0)) / spec.area
        return np.array([max(balance, spec.supply_pressure) / self.pressure_pa])

    def flows(self, q: np.ndarray, v: np.ndarray, p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(Q_check, Q_leak) in m³/s at model pressure p."""
        pa = p * self.pressure_pa
        return np.asarray(check_flow(self.place.hla, pa)), np.asarray(leakage(self.place.hla, pa))

    def evaluate(self, t, q: np.ndarray, v: np.ndarray, s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:  # noqa: ANN001
        if np.ndim(s) == 1:
            return self.evaluate_one(q, v, float(s[0]))
        spec = self.place.hla
        p = s[0]
        u = self.elongation(q)
        push = self.adjuster_force(q, v, p) / self.force_n  # model force
        on_b = -self.sigma * push + self.stiffness * u
        force = np.zeros(np.shape(q))
        (ia, sa), (ib, sb) = self.ends
        if ib >= 0:
            force[ib] += sb * on_b
        if ia >= 0:
            force[ia] -= sa * on_b
        pa = p * self.pressure_pa
        x = self.extension(q) * self.length_m
        xd = self.extension(v) * self.length_m
        flow = check_flow(spec, pa) - leakage(spec, pa) - spec.area * xd
        rate = bulk_modulus(spec, pa) / spec.volume(x) * flow / self.pressure_pa
        return force, np.reshape(rate, np.shape(s))

    def evaluate_one(self, q: np.ndarray, v: np.ndarray, p: float) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`evaluate` at one instant in plain floats (the integrator's right-hand side: the same
        arithmetic, a tenth of the time of the array path)."""
        spec = self.place.hla
        (ia, sa), (ib, sb) = self.ends
        u = (sb * q[ib] if ib >= 0 else 0.0) - (sa * q[ia] if ia >= 0 else 0.0)
        ud = (sb * v[ib] if ib >= 0 else 0.0) - (sa * v[ia] if ia >= 0 else 0.0)
        x, xd = -self.sigma * u * self.length_m, -self.sigma * ud * self.length_m
        pa = p * self.pressure_pa
        push = (pa * self.area + spec.spring_preload - spec.spring_rate * x - spec.damping * xd) / self.force_n
        on_b = -self.sigma * push + self.stiffness * u
        force = np.zeros(len(q))
        if ib >= 0:
            force[ib] += sb * on_b
        if ia >= 0:
            force[ia] -= sa * on_b
        opening = spec.supply_pressure - pa - spec.crack_pressure
        flow = (spec.check_conductance * opening if opening > 0.0 else 0.0) - self.leak_conductance * (
            pa - spec.supply_pressure) - self.area * xd
        rate = self.bulk(pa) / (spec.chamber_volume + self.area * x) * flow / self.pressure_pa
        return force, np.array([rate])

    def bulk(self, pa: float) -> float:
        """K(p) at one gauge pressure (Pa): :func:`bulk_modulus` in floats."""
        spec = self.place.hla
        pressures, moduli = spec.bulk_pressures, spec.bulk_moduli
        if pa <= pressures[0]:
            oil = moduli[0]
        elif pa >= pressures[-1]:
            oil = moduli[-1]
        else:
            j = bisect.bisect_right(pressures, pa)
            w = (pa - pressures[j - 1]) / (pressures[j] - pressures[j - 1])
            oil = moduli[j - 1] + w * (moduli[j] - moduli[j - 1])
        if spec.air_fraction == 0.0:
            return oil
        absolute = max(pa + ATMOSPHERE, 1.0)
        ratio = spec.air_fraction * ATMOSPHERE / absolute
        eps = ratio / (1.0 - spec.air_fraction + ratio)
        return 1.0 / ((1.0 - eps) / oil + eps / absolute)

    def columns(self, t: np.ndarray, q: np.ndarray, v: np.ndarray, s: np.ndarray) -> list[tuple[str, str, np.ndarray]]:
        units = self.units
        q_check, q_leak = self.flows(q, v, s[0])
        volume_rate = f"{units.length}^3/{units.time}"
        per = self.length_m**3
        return [("hla_pressure", units.pressure, s[0]),
                ("hla_plunger_extension", units.length, self.extension(q)),
                ("hla_force", units.force, self.adjuster_force(q, v, s[0]) / self.force_n),
                ("hla_check_flow", volume_rate, q_check / per),
                ("hla_leak_flow", volume_rate, q_leak / per)]

    def summary(self, trace, s: np.ndarray) -> dict:  # noqa: ANN001 (a Trace)
        return train_report(self, trace, s)

    def summary_text(self, entry: dict) -> list[str]:
        return train_text(entry)


def check_events(angle: np.ndarray, opening: np.ndarray) -> list[tuple[float, str]]:
    """(cam angle, "open" | "close") of the check valve's changes on the rows (at the output interval)."""
    changes = np.flatnonzero(opening[1:] != opening[:-1]) + 1
    return [(float(angle[i]), "open" if opening[i] else "close") for i in changes]


def base_circle_angle(trace) -> float:  # noqa: ANN001 (a Trace)
    """The cam angle (deg, 0..360) of the cam coordinate's lowest position in the first revolution."""
    cam = trace.coordinate(trace.spec.cam.coordinate)
    first = trace.cam_angle < 360.0 - 1e-9
    if not first.any():
        return 0.0
    return float(trace.cam_angle[first][int(np.argmin(cam[first]))] % 360.0)


def per_cycle(element: HLAElement, trace, s: np.ndarray) -> dict:  # noqa: ANN001 (a Trace)
    """Cycle by cycle (from each base circle to the next): the plunger's extension at the base circle, its
    drift (pump-up: positive, the adjuster lengthens), its travel (largest minus smallest extension), the
    leak-down and the pump-in (oil volumes through the gap and the check valve over the plunger area), and the
    valve's lift at the base circle. Lengths in model units."""
    angle, time = trace.cam_angle, trace.time
    q, v = trace.q[:, :element.n].T, trace.qd[:, :element.n].T
    extension = element.extension(q)
    q_check, q_leak = element.flows(q, v, s[0])
    area = element.place.hla.area / element.length_m**2  # model length^2
    per = element.length_m**3
    theta = base_circle_angle(trace)
    marks = theta + 360.0 * np.arange(int((angle[-1] - theta) // 360.0) + 1) if len(angle) else np.zeros(0)
    marks = marks[(marks >= angle[0]) & (marks <= angle[-1] + 1e-9)]
    at_marks = np.interp(marks, angle, extension)
    lift = trace.valve_lift() if trace.valve_coordinate() is not None else None
    travel, leak, pumped = [], [], []
    for a, b in zip(marks[:-1], marks[1:], strict=True):
        rows = (angle >= a - 1e-9) & (angle <= b + 1e-9)
        travel.append(float(np.ptp(extension[rows])))
        leak.append(float(np.trapezoid(q_leak[rows], time[rows]) / per / area))
        pumped.append(float(np.trapezoid(q_check[rows], time[rows]) / per / area))
    return {"base_circle_angle": theta, "extension": at_marks.tolist(), "drift": np.diff(at_marks).tolist(),
            "travel": travel, "leak_down": leak, "pump_in": pumped,
            "valve_lift": [] if lift is None else np.interp(marks, angle, lift).tolist()}


def train_report(element: HLAElement, trace, s: np.ndarray) -> dict:  # noqa: ANN001 (a Trace)
    """The run's HLA figures for the summary (``*_unit`` keys)."""
    units = element.units
    p = s[0]
    q, v = trace.q[:, :element.n].T, trace.qd[:, :element.n].T
    q_check, _ = element.flows(q, v, p)
    events = check_events(trace.cam_angle, q_check > 0.0)
    cycles = per_cycle(element, trace, s)
    drift = cycles["drift"]
    return {
        "pressure_max": float(p.max()), "pressure_min": float(p.min()), "pressure_unit": units.pressure,
        "check_valve_events": [{"cam_angle_deg": a, "kind": k} for a, k in events],
        "check_valve_openings": sum(k == "open" for _, k in events),
        "base_circle_angle_deg": cycles["base_circle_angle"],
        "extension_per_cycle": cycles["extension"], "drift_per_cycle": drift,
        "travel_per_cycle": cycles["travel"], "leak_down_per_cycle": cycles["leak_down"],
        "pump_in_per_cycle": cycles["pump_in"], "base_circle_valve_lift_per_cycle": cycles["valve_lift"],
        "last_drift": drift[-1] if drift else None,
        "length_unit": units.length,
    }


def train_text(entry: dict) -> list[str]:
    """The summary's HLA lines."""
    unit, length = entry["pressure_unit"], entry["length_unit"]
    lines = [f"HLA chamber pressure {entry['pressure_min']:.4g} .. {entry['pressure_max']:.4g} {unit}; "
             f"check valve opened {entry['check_valve_openings']} times"]
    if entry["drift_per_cycle"]:
        drift = ", ".join(f"{d:.3g}" for d in entry["drift_per_cycle"])
        travel = ", ".join(f"{d:.3g}" for d in entry["travel_per_cycle"])
        leak = ", ".join(f"{d:.3g}" for d in entry["leak_down_per_cycle"])
        lines.append(f"HLA plunger drift per cycle at the base circle ({entry['base_circle_angle_deg']:.0f} deg; "
                     f"{length}; + pump-up): {drift}")
        lines.append(f"HLA plunger travel per cycle ({length}): {travel}; leak-down per cycle ({length}): {leak}")
    else:
        lines.append("HLA drift per cycle: fewer than two base circles in the run (run.cycles >= 2 to see it)")
    return lines
