"""A valve-train preset's ``[follower]`` and ``[checks]`` tables (explicit form) <-> spec.

``[follower]`` gives the follower's geometry, from which the cam's shape and
the contact stress follow (:mod:`vtool.solvers.model.camshape`,
:mod:`vtool.solvers.model.camstress`)::

    [follower]
    kind = "roller"            # or "flat"
    arrangement = "finger"     # or "translating" (bucket, tappet, roller lifter), "rocker" (centre pivot)
    base_radius = 16.0         # cam base circle (profile), length
    width = 10.0               # contact length (roller or cam lobe width), length
    roller_radius = 9.0        # roller only
    face_diameter = 30.0       # flat only, optional: the face's diameter (contact travel limit)
    cam_modulus = 205000.0     # pressure unit; default steel, 205 GPa
    cam_poisson = 0.3
    follower_modulus = 205000.0
    follower_poisson = 0.3
    roller_arm = 20.0          # finger or rocker only (FingerSpec): pivot to roller centre, along the lever
    valve_arm = 45.0           #   pivot to the valve pad's centre
    roller_height = 0.0        #   roller centre above the pivot-pad line
    cam_offset = 0.0           #   cam centre beyond the roller centre, along the finger
    [follower.lift]            # the lift law at the cam, when it is not [cam] (a finger's)
    profile = "table"          # keys as [cam]: amplitude, or angles/lifts/lift_table and harmonics/tolerance
    [follower.oil]             # optional: the oil film (Dowson-Higginson)
    viscosity = 10.0           # mPa*s (= cP), at the contact's inlet temperature
    pressure_viscosity = 20.0  # 1/GPa

``[checks]`` holds limits by name (:data:`vtool.solvers.studies.checks.CHECKS`),
each in the unit its check states.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from vtool.errors import InputError
from vtool.presets.fields import Table, closest
from vtool.solvers.model.spec import (
    ARRANGEMENTS,
    FLAT,
    FOLLOWER_KINDS,
    LEVERS,
    ROLLER,
    TRANSLATING,
    CamSpec,
    CheckLimit,
    FingerSpec,
    FollowerSpec,
    OilSpec,
)
from vtool.solvers.studies.checks import CHECKS, unit_of
from vtool.units import UnitSystem

STEEL_MODULUS_PA = 205e9  # default modulus of cam and follower (steel), Pa
STEEL_POISSON = 0.3
LENGTH = (1e-6, 1e4)
MPA_S = 1e-3  # Pa s per mPa s
PER_GPA = 1e-9  # 1/Pa per 1/GPa

FINGER_KEYS = ("roller_arm", "valve_arm", "roller_height", "cam_offset")


def load_follower(t: Table, units: UnitSystem, read_law: Callable[[Table], CamSpec]) -> FollowerSpec:
    """Validate ``[follower]``; ``read_law`` reads its ``[follower.lift]`` table (the [cam] keys)."""
    L = units.length
    kind = t.string("kind", choices=FOLLOWER_KINDS)
    arrangement = t.string("arrangement", default=TRANSLATING, choices=ARRANGEMENTS)
    base = t.number("base_radius", unit=L, min_exclusive=0.0, max_value=LENGTH[1])
    width = t.number("width", unit=L, min_exclusive=0.0, max_value=LENGTH[1])
    roller = 0.0
    if kind == ROLLER:
        roller = t.number("roller_radius", unit=L, min_exclusive=0.0, max_value=LENGTH[1])
    elif t.has("roller_radius"):
        raise InputError(t.field("roller_radius"), t.raw("roller_radius"), 'no roller radius for kind = "flat"', L)
    face = None
    if kind == FLAT:
        face = t.number("face_diameter", unit=L, required=False, min_exclusive=0.0, max_value=LENGTH[1])
    steel = STEEL_MODULUS_PA / units.pascals_per_pressure
    moduli = {}
    for part in ("cam", "follower"):
        moduli[f"{part}_modulus"] = t.number(f"{part}_modulus", unit=units.pressure, default=steel,
                                             min_exclusive=0.0, max_value=1e13)
        moduli[f"{part}_poisson"] = t.number(f"{part}_poisson", default=STEEL_POISSON, min_value=0.0,
                                             max_exclusive=0.5)
    finger = None
    if arrangement in LEVERS:
        if kind != ROLLER:
            raise InputError(t.field("kind"), kind, f'roller for a {arrangement} (flat-faced levers are not modelled)')
        arm = t.number("roller_arm", unit=L, min_exclusive=0.0, max_value=LENGTH[1])
        valve = t.number("valve_arm", unit=L, min_exclusive=arm, max_value=LENGTH[1])
        height = t.number("roller_height", unit=L, default=0.0, min_value=-LENGTH[1], max_value=LENGTH[1])
        offset = t.number("cam_offset", unit=L, default=0.0, min_exclusive=-(base + roller),
                          max_exclusive=base + roller)
        finger = FingerSpec(arm, valve, height, offset)
    else:
        for key in FINGER_KEYS:
            if t.has(key):
                raise InputError(t.field(key), t.raw(key), 'only with arrangement = "finger" or "rocker"', L)
    lift_table = t.table("lift", required=False)
    lift = None if lift_table is None else read_law(lift_table)
    oil = None
    oil_table = t.table("oil", required=False)
    if oil_table is not None:
        viscosity = oil_table.number("viscosity", unit="mPa*s", min_exclusive=0.0, max_value=1e6)
        alpha = oil_table.number("pressure_viscosity", unit="1/GPa", min_value=0.0, max_value=100.0)
        oil_table.finish()
        oil = OilSpec(viscosity * MPA_S, alpha * PER_GPA)
    friction = t.number("friction", default=0.0, min_value=0.0, max_value=1.0)
    guide = t.number("guide_friction", unit=units.force, default=0.0, min_value=0.0, max_value=1e9)
    guide_velocity = t.number("guide_velocity", unit=f"{L}/s", default=1e-3 / units.metres_per_length,
                              min_exclusive=0.0, max_value=1e9)
    from vtool.presets.friction import load_friction

    laws = load_friction(t, units, kind == ROLLER, arrangement in LEVERS, friction, guide)
    t.finish()
    return FollowerSpec(kind, arrangement, base, width, roller, face, finger=finger, lift=lift, oil=oil,
                        friction=friction, guide_friction=guide, guide_velocity=guide_velocity, laws=laws, **moduli)


def dump_follower(f: FollowerSpec, dump_law: Callable[[CamSpec], dict[str, Any]]) -> dict[str, Any]:
    """The ``[follower]`` table of a spec (inverse of :func:`load_follower`)."""
    doc: dict[str, Any] = {"kind": f.kind, "arrangement": f.arrangement, "base_radius": f.base_radius,
                           "width": f.width}
    if f.kind == ROLLER:
        doc["roller_radius"] = f.roller_radius
    if f.face_diameter is not None:
        doc["face_diameter"] = f.face_diameter
    doc |= {"cam_modulus": f.cam_modulus, "cam_poisson": f.cam_poisson, "follower_modulus": f.follower_modulus,
            "follower_poisson": f.follower_poisson}
    if f.friction:
        doc["friction"] = f.friction
    if f.guide_friction:
        doc |= {"guide_friction": f.guide_friction, "guide_velocity": f.guide_velocity}
    from vtool.presets.friction import dump_friction

    doc |= dump_friction(f.laws)
    if f.finger is not None:
        doc |= {key: getattr(f.finger, key) for key in FINGER_KEYS}
    if f.lift is not None:
        doc["lift"] = dump_law(f.lift)
    if f.oil is not None:
        doc["oil"] = {"viscosity": f.oil.viscosity / MPA_S, "pressure_viscosity": f.oil.pressure_viscosity / PER_GPA}
    return doc


def load_checks(t: Table, units: UnitSystem) -> tuple[CheckLimit, ...]:
    """Validate ``[checks]``: known names only, each a finite number in its check's unit."""
    result = []
    names = sorted(CHECKS)
    for key in list(t.data):
        if key not in CHECKS:
            raise InputError(t.field(key), t.raw(key), f"one of the checks: {', '.join(names)}{closest(key, names)}")
        unit = check_units(units)[key]
        limit = t.number(key, unit=unit, min_value=-1e12, max_value=1e12)
        result.append(CheckLimit(key, limit))
    t.finish()
    return tuple(result)


def check_units(units: UnitSystem) -> dict[str, str]:
    """Each check name's unit in a unit system (for docs and forms)."""

    class _Spec:  # unit_of reads only .unit_system
        unit_system = units

    return {name: unit_of(_Spec, kind.unit_kind) for name, kind in CHECKS.items()}  # type: ignore[arg-type]  # unit_of reads only .unit_system, which _Spec has
