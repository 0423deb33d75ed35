"""``[valve_forces]``: guide friction and the gas force acting on the valve (:mod:`vtool.solvers.model.valveforces`).

Keys (the preset's units; mm-N-s: N, mm/s, N*s/mm, MPa, mm, crank degrees):
``coordinate`` (default: the valve, the seat clearance's ahead coordinate),
``guide_friction`` (F_c), ``guide_velocity`` (v_r, default 1 length/s),
``static_friction`` (F_s, the Stribeck peak; default F_c), ``stribeck_velocity``
(v_s, required with ``static_friction``), ``viscous`` (c_v); ``gas_crank_angles``
and ``gas_pressures`` (the cylinder pressure over one 720-degree cycle, gauge),
``head_diameter``, ``seat_side`` (``"cylinder"``: the pressure presses the
valve onto its seat, or ``"port"``), ``gas_phase`` (crank angle at cam angle
zero). A train preset gives the same table (it passes through the type's
expansion). The forces act on the motion: a preset with them runs on a back end
that takes nonlinear elements (scipy).
"""

from __future__ import annotations

from typing import Any

from vtool.errors import InputError
from vtool.presets.fields import Table
from vtool.solvers.model.valveforces import SEAT_SIDES, ValveForces
from vtool.units import UnitSystem

KEYS = ("coordinate", "guide_friction", "guide_velocity", "static_friction", "stribeck_velocity", "viscous",
        "gas_crank_angles", "gas_pressures", "head_diameter", "seat_side", "gas_phase")


def load_valve_forces(t: Table, units: UnitSystem, n: int) -> ValveForces:
    """The ``[valve_forces]`` table (module doc); ``n``: the explicit model's coordinates."""
    coordinate = t.integer("coordinate", min_value=1, max_value=n) if t.has("coordinate") else None
    if not t.has("coordinate"):
        t.raw("coordinate")  # (noted for the reference: optional)
    velocity, force = units.velocity, units.force
    friction = t.number("guide_friction", unit=force, default=0.0, min_value=0.0, max_value=1e9)
    regular = t.number("guide_velocity", unit=velocity, default=1.0, min_exclusive=0.0, max_value=1e9)
    peak = t.number("static_friction", unit=force, required=False, min_value=friction, max_value=1e9)
    stribeck = t.number("stribeck_velocity", unit=velocity, default=None if peak is not None else 1.0,
                        min_exclusive=0.0, max_value=1e9)
    viscous = t.number("viscous", unit=f"{force}*{units.time}/{units.length}", default=0.0, min_value=0.0,
                       max_value=1e9)
    angles = t.numbers("gas_crank_angles", unit="crank deg", default=[])
    pressures = t.numbers("gas_pressures", unit=units.pressure, default=[])
    if len(angles) != len(pressures):
        raise InputError(t.field("gas_pressures"), pressures, f"as many values as gas_crank_angles ({len(angles)})",
                         units.pressure)
    if angles and (any(b <= a for a, b in zip(angles, angles[1:], strict=False)) or angles[0] < 0.0
                   or angles[-1] >= 720.0):
        raise InputError(t.field("gas_crank_angles"), angles, "increasing, within [0, 720)", "crank deg")
    if any(not -1e9 <= p <= 1e9 for p in pressures):
        raise InputError(t.field("gas_pressures"), pressures, "finite, within +-1e9", units.pressure)
    head = t.number("head_diameter", unit=units.length, default=None if angles else 0.0,
                    min_value=0.0 if not angles else None, min_exclusive=0.0 if angles else None, max_value=1e4)
    side = t.string("seat_side", default="cylinder", choices=SEAT_SIDES)
    phase = t.number("gas_phase", unit="crank deg", default=0.0, min_value=-720.0, max_value=720.0)
    t.finish()
    return ValveForces(coordinate, friction, regular, peak, stribeck, viscous, tuple(angles), tuple(pressures), head,
                       side, phase)


def dump_valve_forces(vf: ValveForces) -> dict[str, Any]:
    """The ``[valve_forces]`` table of a spec."""
    doc: dict[str, Any] = {} if vf.coordinate is None else {"coordinate": vf.coordinate}
    doc |= {"guide_friction": vf.guide_friction, "guide_velocity": vf.guide_velocity, "viscous": vf.viscous}
    if vf.static_friction is not None:
        doc |= {"static_friction": vf.static_friction, "stribeck_velocity": vf.stribeck_velocity}
    if vf.gas_angles:
        doc |= {"gas_crank_angles": list(vf.gas_angles), "gas_pressures": list(vf.gas_pressures),
                "head_diameter": vf.head_diameter, "seat_side": vf.seat_side, "gas_phase": vf.gas_phase}
    return doc
