"""Checks on an assembled mechanism before a run: does the valve reach its seat; can the result be trusted?

:func:`run_warnings` gathers every check's one-line warning; the run
(:func:`vtool.solvers.run.simulate`) issues them as PresetWarnings.

**Seat.**

Quasi-statically every coordinate follows the static-start shape scaled by the
cam (:mod:`vtool.solvers.model.initial`: q = q₀ q_cam / q_cam(0)), and the cam
moves as q_cam = base + L(θ) over its lift law's whole range (the harmonic
cam's L = A + A sin θ, a lift table's fitted series: :mod:`vtool.solvers.model.cam`),
sampled at every 0.1 deg. So the valve coordinate v of the seat clearance
(gap = q_v − seat) travels over

    q_v ∈ q_v0 (base + [min L, max L]) / q_cam(0)

and when the seat lies below that whole range the seat clearance never
closes except by a dynamic overshoot: the run is valid but probably not what
the preset meant (e.g. a sign slip in ``seat.position``). That is reported as
a warning, not an error. A preset set by its lash seats the valve wherever
the lift is below the lash, so it passes whenever its cam has a base circle.
"""

from __future__ import annotations

import numpy as np

from vtool.solvers.model.cam import derivatives, lift_series
from vtool.solvers.model.mechanism import Mechanism
from vtool.solvers.model.spec import ENABLED, EXTERNAL, MOMENTUM, MechanismSpec

SAMPLES = 3600  # cam angles at which the lift law is evaluated (0.1 deg apart)
#: below this modal damping ratio (times the factor) a run is "nearly undamped" (see damping_warning)
LOW_DAMPING = 0.01
#: ... and a run longer than this (deg) has had the time to drift apart between back ends
LONG_RUN_DEG = 360.0


def lift_range(mechanism: Mechanism) -> tuple[float, float, float]:
    """(L(0), lowest, highest L) of the cam's lift law, relative to its mean c0, at SAMPLES angles over
    a revolution: the cam's alone, so kept with the mechanism for every run of it (100 µs a run)."""

    def make() -> tuple[float, float, float]:
        c0, a, b = lift_series(mechanism.spec.cam)
        lift = derivatives(c0, a, b, np.arange(SAMPLES) * (2.0 * np.pi / SAMPLES))[0] - c0
        return float(lift[0]), float(lift.min()), float(lift.max())

    return mechanism.shared("cam lift range", make)


def cam_travel(mechanism: Mechanism) -> tuple[float, float, float]:
    """(q_cam(0), lowest, highest q_cam) over a revolution of the cam's lift law (length units)."""
    offset = mechanism.start.cam_offset
    start, lowest, highest = lift_range(mechanism)
    return offset + start, offset + lowest, offset + highest


def seat_reach_warning(mechanism: Mechanism) -> str | None:
    """A one-line warning when the valve never reaches the seat quasi-statically, else None."""
    spec = mechanism.spec
    seat = spec.seat
    if seat is None:
        return None
    start_cam, lowest, highest = cam_travel(mechanism)
    if start_cam == 0.0:
        return None
    units = spec.unit_system
    for c in spec.clearances:
        if c.kind != EXTERNAL or c.behind != seat.coordinate or c.state != ENABLED:
            continue
        start = float(mechanism.start.q[c.ahead - 1])
        low, high = sorted((start * lowest / start_cam, start * highest / start_cam))
        if low > seat.position:
            return (f"seat.position: the valve (q{c.ahead}) moves between {low:.4g} and {high:.4g} "
                    f"{units.length} with the cam, never down to the seat at {seat.position:.4g} "
                    f"{units.length}; clearance '{c.name}' closes only by dynamic overshoot")
    return None


def elastic_impact_warning(spec: MechanismSpec) -> str | None:
    """A warning when a rigid clearance with restitution 1 uses an impact law that is not energy-conserving.

    The ``local`` law (thesis eq. 3.53) and the ``thesis`` law (eq. 3.54's
    SCALE) change one coordinate's velocity (or a merged pair's) with the
    diagonal masses, while the model's mass matrix is consistent (coupled):
    at e = 1 an impact keeps the pair's energy, not the system's kinetic
    energy (the energy of a bar struck again and again drifts up or down).
    The ``momentum`` law solves the impact on the consistent mass matrix and
    conserves it (tests/test_impact_laws.py).
    """
    named = [f"{c.name} ({spec.impact_law(c)})" for c in spec.clearances
             if c.state == ENABLED and c.rigid and c.restitution >= 1.0 and spec.impact_law(c) != MOMENTUM]
    if not named:
        return None
    return (f"restitution: 1 at {', '.join(named)}: these impact laws do not conserve kinetic energy with the "
            f"consistent mass matrix (the energy drifts from impact to impact); impact = \"momentum\" does")


def least_damping(spec: MechanismSpec) -> float:
    """The smallest modal damping ratio any layer gives an elastic mode, times the global factor."""
    d = spec.damping
    ratios = [d.default_ratio] + [layer.default_ratio for layer in d.layers]
    ratios += [ratio for layer in d.layers for _, ratio in layer.mode_ratios]
    return d.factor * min(ratios)


def damping_warning(spec: MechanismSpec) -> str | None:
    """A warning when a long run is (nearly) undamped: its result depends on the back end and the step.

    Impacts excite the highest modes; with no damping their errors (each back
    end's own: Newmark's period error, scipy's tolerance, the exact back
    end's event location) never die out and move every later event, so
    after a revolution or so two back ends can differ several times in their
    peaks (3.5 times on an undamped gnilka-1a). Warned for a modal damping
    ratio below :data:`LOW_DAMPING` over more than :data:`LONG_RUN_DEG`.
    """
    zeta = least_damping(spec)
    if zeta >= LOW_DAMPING or spec.run.degrees <= LONG_RUN_DEG:
        return None
    return (f"damping: a modal damping ratio of {zeta:.3g} (below {LOW_DAMPING:g}) over {spec.run.degrees:g} deg: "
            f"a nearly undamped run is sensitive to the back end and the step (peaks can differ several times "
            f"between back ends); check it with `vtool compare` or a smaller step")


def run_warnings(mechanism: Mechanism) -> list[str]:
    """Every preflight warning for this run (one line each)."""
    checks = (seat_reach_warning(mechanism), elastic_impact_warning(mechanism.spec), damping_warning(mechanism.spec))
    return [w for w in checks if w is not None]
