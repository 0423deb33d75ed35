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

The element is a model of its own here (:func:`simulate`, scipy's LSODA):
it is not yet a part of a valve-train preset's chain, so no back end takes it.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

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
