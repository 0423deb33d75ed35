"""The friction-law keys of a ``[follower]`` table (:class:`vtool.solvers.model.friction.FrictionLaws`).

Read by :func:`vtool.presets.follower.load_follower` from the same table (a
train's ``[train.follower]`` too), after its coefficients ``friction`` (μ of
the cam contact) and ``guide_friction`` (the guide's force)::

    friction_law = "stribeck"     # the sliding contacts' law: coulomb (default) or stribeck
    static_friction = 0.15        # stribeck: μ_s of the cam contact (default: friction)
    guide_static_friction = 20.0  # stribeck: the guide's force at rest (default: guide_friction)
    stribeck_velocity = 10.0      # stribeck: v_S, length/s (default 10 mm/s)
    viscous_friction = 0.0        # stribeck: k_v, s/length
    pivot_friction = 0.1          # finger/rocker: the pivot's μ ...
    pivot_radius = 4.0            # ... on a pin (ball) of this radius, length
    pivot_velocity = 1.0          # ... regularised below this angular velocity, rad/s
    slip_friction = 0.1           # roller: μ_slip, the traction limit (0: slip not evaluated) ...
    roller_inertia = 2.0e-6       # ... with the roller's moment of inertia about its pin, mass*length^2

The laws are stated in :mod:`vtool.solvers.model.friction`.
"""

from __future__ import annotations

from typing import Any

from vtool.errors import InputError
from vtool.presets.fields import Table
from vtool.solvers.model.friction import COULOMB, SLIDING_LAWS, STRIBECK, FrictionLaws
from vtool.units import UnitSystem

KEYS = ("friction_law", "static_friction", "guide_static_friction", "stribeck_velocity", "viscous_friction",
        "pivot_friction", "pivot_radius", "pivot_velocity", "slip_friction", "roller_inertia")


def load_friction(t: Table, units: UnitSystem, roller: bool, lever: bool, friction: float,
                  guide: float) -> FrictionLaws | None:
    """The friction-law keys of ``t`` (module doc); None when none is given."""
    if not any(t.has(key) for key in KEYS):
        return None
    L = units.length
    sliding = t.string("friction_law", default=COULOMB, choices=SLIDING_LAWS)
    values: dict[str, Any] = {"sliding": sliding}
    stribeck_keys = ("static_friction", "guide_static_friction", "stribeck_velocity", "viscous_friction")
    if sliding == STRIBECK:
        values["static"] = t.number("static_friction", default=friction, min_value=friction, max_value=1.0)
        values["guide_static"] = t.number("guide_static_friction", unit=units.force, default=guide,
                                          min_value=guide, max_value=1e9)
        values["stribeck_velocity"] = t.number("stribeck_velocity", unit=f"{L}/s",
                                               default=1e-2 / units.metres_per_length, min_exclusive=0.0,
                                               max_value=1e9)
        values["viscous"] = t.number("viscous_friction", unit=f"s/{L}", default=0.0, min_value=0.0, max_value=1e9)
    else:
        for key in stribeck_keys:
            if t.has(key):
                raise InputError(t.field(key), t.raw(key), 'only with friction_law = "stribeck"')
    if t.has("pivot_friction") or t.has("pivot_radius"):
        if not lever:
            raise InputError(t.field("pivot_friction"), t.raw("pivot_friction") if t.has("pivot_friction") else None,
                             'only with arrangement = "finger" or "rocker" (a pivot)')
        values["pivot"] = t.number("pivot_friction", min_value=0.0, max_value=1.0)
        values["pivot_radius"] = t.number("pivot_radius", unit=L, min_exclusive=0.0, max_value=1e9)
        values["pivot_velocity"] = t.number("pivot_velocity", unit="rad/s", default=1.0, min_exclusive=0.0,
                                            max_value=1e6)
    if t.has("slip_friction") or t.has("roller_inertia"):
        if not roller:
            raise InputError(t.field("slip_friction"), t.raw("slip_friction") if t.has("slip_friction") else None,
                             'only with kind = "roller"')
        values["slip"] = t.number("slip_friction", min_exclusive=0.0, max_value=1.0)
        values["roller_inertia"] = t.number("roller_inertia", unit=f"{units.mass}*{L}^2", min_exclusive=0.0,
                                            max_value=1e9)
    return FrictionLaws(**values)


def dump_friction(laws: FrictionLaws | None) -> dict[str, Any]:
    """The keys :func:`load_friction` reads back to ``laws``."""
    if laws is None:
        return {}
    doc: dict[str, Any] = {"friction_law": laws.sliding}
    if laws.sliding == STRIBECK:
        doc |= {"static_friction": laws.static, "guide_static_friction": laws.guide_static,
                "stribeck_velocity": laws.stribeck_velocity, "viscous_friction": laws.viscous}
    if laws.pivot_radius:
        doc |= {"pivot_friction": laws.pivot, "pivot_radius": laws.pivot_radius,
                "pivot_velocity": laws.pivot_velocity}
    if laws.slip:
        doc |= {"slip_friction": laws.slip, "roller_inertia": laws.roller_inertia}
    return doc
