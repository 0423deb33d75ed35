"""Valve lash: the follower clearance on the base circle, and the seat position it implies.

With the cam on its base circle (L = 0, q_cam = base) and the valve on its
seat, the cam contact is open and the valve train rests in the static state
the seat alone holds: in the starting contact layer (rocker closed),
K_L y = e_v, scaled so that the valve coordinate v is at the seat position s.
The follower f then sits at q_f = r s with r = y_f / y_v, so

    lash = r s - base,        s = (base + lash) / r

``base`` is where the cam puts the follower on its base circle: the thesis'
static-start rule base = F_s R / k_eff (spring preload F_s through the lever
ratio R, k_eff = 1 / (K_L⁻¹)_ff the static stiffness at the follower) for
``offset = "static-start"``, else offset - A for a harmonic cam. A positive
lash is a gap; a negative one means the valve cannot close on the base circle.
"""

from __future__ import annotations

import numpy as np

from vtool.errors import InputError
from vtool.solvers.model.spec import EXTERNAL, MechanismSpec


def _seat_clearance(spec: MechanismSpec):
    for c in spec.clearances:
        if spec.seat is not None and c.kind == EXTERNAL and c.behind == spec.seat.coordinate:
            return c
    raise InputError("seat.lash", None, "a clearance with behind = the seat coordinate")


def base_and_ratio(spec: MechanismSpec) -> tuple[float, float]:
    """(base, r): the follower on the base circle and q_f / q_v with the valve seated (module doc)."""
    from vtool.solvers.model.initial import cam_clearance, start_stiffness
    from vtool.solvers.model.mechanism import Mechanism

    layer = Mechanism(spec).start_layer
    stiffness = start_stiffness(spec, layer)  # with the springs of compliant contacts closed at the start

    def unit_load_response(coordinate: int) -> np.ndarray:
        load = np.zeros(layer.size)
        load[int(np.argmax(layer.T[coordinate - 1]))] = 1.0
        try:
            return layer.T @ np.linalg.solve(stiffness, load)
        except np.linalg.LinAlgError:
            raise InputError("members", "no spring to ground",
                             "a mechanism that is statically stable with the cam released") from None

    follower = cam_clearance(spec).ahead
    valve = _seat_clearance(spec).ahead
    k_eff = 1.0 / unit_load_response(follower)[follower - 1]
    if spec.cam.offset is None:
        base = spec.initial.spring_preload * spec.initial.lever_ratio / k_eff
    else:
        base = spec.cam.offset - spec.cam.amplitude
    y = unit_load_response(valve)
    if abs(y[follower - 1]) < 1e-12 * abs(y[valve - 1]):
        raise InputError("seat.lash", spec.seat.lash if spec.seat else None,
                         "a seat whose valve moves the follower (use seat.position)")
    return base, float(y[follower - 1] / y[valve - 1])


def seat_position(spec: MechanismSpec, lash: float) -> float:
    """The seat position (thesis CLEAR) that gives this lash."""
    base, r = base_and_ratio(spec)
    return (base + lash) / r


def lash_of(spec: MechanismSpec) -> float:
    """The lash the spec's seat position gives (length units)."""
    base, r = base_and_ratio(spec)
    return r * spec.seat.position - base  # type: ignore[union-attr]  # a lash preset has a seat (the loader checks)
