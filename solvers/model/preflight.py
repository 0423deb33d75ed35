"""Checks on an assembled mechanism before a run: does the valve ever reach its seat?

Quasi-statically every coordinate follows the static-start shape scaled by the
cam (:mod:`vtool.solvers.model.initial`: q = q₀ q_cam / XZERO), and the harmonic
cam moves between XZERO − A and XZERO + A. So the valve coordinate v of the
seat clearance (gap = q_v − seat) travels over

    q_v ∈ q_v0 (XZERO ± A) / XZERO

(a lift table: q_v0 (base + L) / (base + L(0)) over its lift L), and when
the seat lies below that whole range the seat clearance never
closes except by a dynamic overshoot: the run is valid but probably not what
the preset meant (e.g. a sign slip in ``seat.position``). That is reported as
a warning, not an error.
"""

from __future__ import annotations

import numpy as np

from vtool.solvers.model.cam import derivatives, lift_series
from vtool.solvers.model.mechanism import Mechanism
from vtool.solvers.model.spec import ENABLED, EXTERNAL


def seat_reach_warning(mechanism: Mechanism) -> str | None:
    """A one-line warning when the valve never reaches the seat quasi-statically, else None."""
    spec = mechanism.spec
    seat = spec.seat
    offset = mechanism.start.cam_offset
    if seat is None or offset == 0.0:
        return None
    # q_cam = base + L(theta), offset = base + c0 (harmonic: c0 = A, L(0) = A, so q_cam(0) = offset and
    # the range is offset -/+ A); a lift table starts at base + L(0), anywhere on its lift
    c0, a, b = lift_series(spec.cam)
    lift = derivatives(c0, a, b, np.linspace(0.0, 2.0 * np.pi, 720, endpoint=False))[0]
    base = offset - c0
    at_start = base + derivatives(c0, a, b, np.zeros(1))[0, 0]
    units = spec.unit_system
    for c in spec.clearances:
        if c.kind != EXTERNAL or c.behind != seat.coordinate or c.state != ENABLED:
            continue
        start = float(mechanism.start.q[c.ahead - 1])
        low, high = sorted((start * (base + lift.min()) / at_start, start * (base + lift.max()) / at_start))
        if low > seat.position:
            return (f"seat.position: the valve (q{c.ahead}) moves between {low:.4g} and {high:.4g} "
                    f"{units.length} with the cam, never down to the seat at {seat.position:.4g} "
                    f"{units.length}; clearance '{c.name}' closes only by dynamic overshoot")
    return None
