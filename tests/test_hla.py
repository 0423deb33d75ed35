"""The hydraulic lash adjuster element (solvers/model/hla.py) against closed-form results."""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from vtool.solvers.model import hla

SPEC = hla.HLASpec(plunger_diameter=10e-3, chamber_volume=300e-9, plunger_mass=5e-3, spring_rate=2e3,
                   spring_preload=15.0, gap=3e-6, gap_length=8e-3, viscosity=0.01, supply_pressure=2e5,
                   check_conductance=1e-9, crack_pressure=5e3, bulk_pressures=(0.0, 3e7), bulk_moduli=(1.5e9, 1.8e9),
                   damping=300.0)


def test_closed_chamber_is_a_spring_k_a2_over_v():
    """Check shut, no leakage, no plunger spring: the static tangent stiffness is K A²/V to 1e-6."""
    spec = dataclasses.replace(SPEC, spring_rate=0.0, spring_preload=0.0, bulk_moduli=(1.6e9, 1.6e9))
    load, delta = 200.0, 10.0
    p0 = load / spec.area
    up = hla.static_extension(spec, load + delta, p0)
    down = hla.static_extension(spec, load - delta, p0)
    stiffness = 2.0 * delta / (down - up)
    expected = 1.6e9 * spec.area**2 / spec.chamber_volume
    assert math.isclose(stiffness, expected, rel_tol=1e-6)
    assert math.isclose(hla.closed_stiffness(spec, p0), expected, rel_tol=1e-12)
    # constant K: p - p0 = K ln(V0 / V) exactly
    exact = spec.chamber_volume * (math.exp(-delta / spec.area / 1.6e9) - 1.0) / spec.area
    assert math.isclose(up, exact, rel_tol=1e-6)


def test_entrained_air_softens_the_oil():
    spec = dataclasses.replace(SPEC, air_fraction=0.01)
    p = np.array([0.0, 1e6, 1e7])
    k = hla.bulk_modulus(spec, p)
    oil = hla.bulk_modulus(SPEC, p)
    assert np.all(k < oil) and np.all(np.diff(k) > 0)  # the air compresses away as the pressure rises
    assert math.isclose(k[0], 1.0 / (0.99 / 1.5e9 + 0.01 / hla.ATMOSPHERE), rel_tol=1e-12)


def test_leak_down_follows_the_gap_formula():
    """A steady load bleeds the plunger down at Q/A, Q = π d h³ Δp / (12 μ L), within 1 %."""
    load = 400.0
    p = (load - SPEC.spring_preload) / SPEC.area
    run = hla.simulate(SPEC, lambda t, x: load, 0.05, (0.0, 0.0, p), rows=501)
    late = run.time > 0.02
    rate = np.polyfit(run.time[late], run.extension[late], 1)[0]
    x = float(run.extension[late].mean())
    dp = (load - SPEC.spring_preload + SPEC.spring_rate * x) / SPEC.area - SPEC.supply_pressure
    q = math.pi * SPEC.plunger_diameter * SPEC.gap**3 * dp / (12.0 * SPEC.viscosity * SPEC.gap_length)
    assert rate < 0.0
    assert math.isclose(rate, -q / SPEC.area, rel_tol=1e-2)
    assert len(run.check_open_times) == 0
    assert math.isclose(hla.leak_down_rate(SPEC, load, x), -q / SPEC.area, rel_tol=1e-12)


def test_pump_up_closes_the_lash_and_settles():
    """A lash opening of 0.1 mm on the base circle: the plunger pumps up until the finger's contact takes
    its spring's load; with a valve event each cycle the drift per cycle then settles towards zero."""
    period, contact = 0.02, 1e7  # 3,000 cam rev/min; the finger's contact stiffness (N/m)
    seat = 0.1e-3  # extension at which the lash closes

    def load(t: float, x: float) -> float:
        phase = (t % period) / period
        event = 300.0 * math.sin(math.pi * phase / 0.35) ** 2 if phase < 0.35 else 0.0
        return contact * max(x - seat, 0.0) + event

    run, drift = hla.pump_up(SPEC, load, period, 12, (0.0, 0.0, SPEC.supply_pressure))
    assert drift[0] > 0.5 * seat  # the first cycle pumps most of the lash up
    assert run.extension.max() < seat + 0.05e-3  # and stops at the contact
    assert len(run.check_open_times) >= 5  # the check valve refills on the base circle
    assert abs(drift[-1]) < 0.02 * drift[0] and abs(drift[-1]) <= abs(drift[-3]) + 1e-9
