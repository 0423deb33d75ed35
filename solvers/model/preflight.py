"""Checks on an assembled mechanism before a run: does the valve ever reach its seat?

Quasi-statically every coordinate follows the static-start shape scaled by the
cam (:mod:`vtool.solvers.model.initial`: q = q₀ q_cam / XZERO), and the harmonic
cam moves between XZERO − A and XZERO + A. So the valve coordinate v of the
seat clearance (gap = q_v − seat) travels over

    q_v ∈ q_v0 (XZERO ± A) / XZERO

and when the seat lies below that whole range the seat clearance never
closes except by a dynamic overshoot: the run is valid but probably not what
the preset meant (e.g. a sign slip in ``seat.position``). That is reported as
a warning, not an error.
"""

from __future__ import annotations

from vtool.solvers.model.mechanism import Mechanism
from vtool.solvers.model.spec import ENABLED, EXTERNAL


def seat_reach_warning(mechanism: Mechanism) -> str | None:
    """A one-line warning when the valve never reaches the seat quasi-statically, else None."""
    spec = mechanism.spec
    seat = spec.seat
    offset = mechanism.start.cam_offset
    if seat is None or offset == 0.0:
        return None
    amplitude = spec.cam.amplitude
    units = spec.unit_system
    for c in spec.clearances:
        if c.kind != EXTERNAL or c.behind != seat.coordinate or c.state != ENABLED:
            continue
        start = float(mechanism.start.q[c.ahead - 1])
        low, high = sorted((start * (offset - amplitude) / offset, start * (offset + amplitude) / offset))
        if low > seat.position:
            return (f"seat.position: the valve (q{c.ahead}) moves between {low:.4g} and {high:.4g} "
                    f"{units.length} with the cam, never down to the seat at {seat.position:.4g} "
                    f"{units.length}; clearance '{c.name}' closes only by dynamic overshoot")
    return None
