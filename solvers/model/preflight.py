"""Checks on an assembled mechanism before a run: does the valve ever reach its seat?

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

from vtool.solvers.model.mechanism import Mechanism
from vtool.solvers.model.spec import ENABLED, EXTERNAL

SAMPLES = 3600  # cam angles at which the lift law is evaluated (0.1 deg apart)


def cam_travel(mechanism: Mechanism) -> tuple[float, float, float]:
    """(q_cam(0), lowest, highest q_cam) over a revolution of the cam's lift law (length units)."""
    omega = mechanism.omega
    period = 2.0 * np.pi / omega if omega > 0.0 else 1.0
    positions = np.asarray(mechanism.cam_position(np.arange(SAMPLES) * (period / SAMPLES)), dtype=float)
    return float(positions[0]), float(positions.min()), float(positions.max())


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
