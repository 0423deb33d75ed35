"""Valve trains entered as an engineer describes them: a ``[train]`` table expanded to the explicit model.

A preset may give ``[train] type = "ohv-pushrod" | "direct-acting" |
"finger-follower"`` with the parts' data instead of coordinates, members and
clearances; :func:`expand` turns it into the explicit document that
:func:`vtool.presets.valvetrain.load` reads (``vtool presets expand P``
prints it), so every back end, study and screen runs it unchanged. The
explicit form stays valid. Top-level keys other than the ones a train builds
(``coordinates``, ``members``, ``cam``, ``seat``, ``clearances``,
``follower``) pass through: ``[run]``, ``[damping]`` (naming the type's
clearances below), ``[contact]``, ``[checks]``, ``[initial] velocities``.

Parts (each table's numbers in the preset's unit system):

* sections (``[train.pushrod]``, ``[train.rocker]``, ``[train.valve]``,
  ``[train.finger]``): the explicit members' keys ``diameter`` or ``area``
  (and ``inertia`` for beams), ``modulus``, ``specific_weight``,
  ``density`` or ``mass``, ``elements``;
* ``[train.spring]``: :mod:`vtool.presets.springs` (rate, preload, mass);
* ``[train.cam]``: the lift law at the cam (for a finger: the roller's
  radial lift, :mod:`vtool.solvers.model.camshape`): ``law = "harmonic"``
  (``lift``: L = lift/2 (1 + sin θ), the thesis' cam), ``"table"`` (the
  [cam] keys ``angles``/``lifts`` or ``lift_table``, ``harmonics`` or
  ``tolerance``) or ``"polydyne"`` (``lift``, ``ramp_height``, ``ramp_deg``,
  ``flank_deg``, the nose at ``nose_deg``: the ramped polydyne of
  :mod:`vtool.presets.ramped_cam`, sampled every ``step_deg`` and fitted to
  ``tolerance``); ``angle_basis =
  "crank"`` reads every angle of the table as crank degrees (halved: the cam
  turns once per two crank turns);
* ``[train.seat]``: ``lash`` (the follower clearance on the base circle, in
  the model's cam coordinate) or ``position``;
* ``[train.follower]`` (optional for ``ohv-pushrod``): the explicit
  [follower] keys without ``arrangement`` and the finger's arms (the type
  sets them), with ``[train.oil]`` its oil.

Types and the clearance names [damping] may use:

* ``ohv-pushrod`` (Gnilka 1971's layout): ``[train.pushrod]`` (``length``),
  ``[train.rocker]`` (``cam_arm``, ``valve_arm``: its pushrod and valve
  arms), ``[train.valve]`` (``length``); clearances ``cam``, ``rocker``,
  ``seat``; coordinates as gnilka-1a (q1 follower .. q8 pushrod top).
* ``direct-acting`` (type I bucket): ``[train.bucket]`` (``mass``,
  ``stiffness``: crown, shim and stem tip in series; ``length`` for
  drawings), ``[train.valve]``; flat follower; clearances ``cam``, ``seat``.
* ``finger-follower`` (type II, end pivot, roller):
  ``[train.finger]`` (``roller_arm``, ``valve_arm``, ``roller_height``,
  ``cam_offset`` as :class:`vtool.solvers.model.spec.FingerSpec`, and a
  beam section), ``[train.pivot]`` (``stiffness``, ``mass``: the support
  under the finger's pivot, a member named ``pivot`` on the coordinate
  ``finger pivot (lash adjuster)``, the place a hydraulic lash adjuster
  takes), ``[train.valve]``; clearances ``cam``, ``pad`` (finger pad on the
  valve tip), ``seat``. The model's finger is a beam lever with the nominal
  ratio valve_arm/roller_arm; its cam coordinate moves as the geometric
  valve lift over that ratio (:func:`vtool.solvers.model.camshape.model_lift`),
  so the valve side follows the finger's varying ratio.
* ``centre-pivot-rocker`` (OHC roller rocker on a shaft): ``[train.rocker]``
  (``roller_arm``, ``valve_arm``, ``roller_height``, ``cam_offset`` and a
  beam section; the roller beyond the pivot from the valve, the cam under
  it), ``[train.valve]``; clearances ``cam``, ``seat``; the valve side
  follows the rocker's varying ratio as a finger's does.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Any

import numpy as np

from vtool.errors import InputError
from vtool.presets.fields import Table
from vtool.presets.lift_table import read_lift_table
from vtool.presets.springs import spring_model
from vtool.units import UNIT_SYSTEMS, UnitSystem

OHV_PUSHROD = "ohv-pushrod"
DIRECT_ACTING = "direct-acting"
FINGER_FOLLOWER = "finger-follower"
CENTRE_PIVOT_ROCKER = "centre-pivot-rocker"
TYPES = (OHV_PUSHROD, DIRECT_ACTING, FINGER_FOLLOWER, CENTRE_PIVOT_ROCKER)

#: top-level tables a train builds (refused beside [train])
BUILT = ("coordinates", "members", "cam", "seat", "clearances", "follower", "hla")
SECTION_KEYS = ("diameter", "area", "inertia", "modulus", "specific_weight", "density", "mass", "stiffness",
                "elements")
LAWS = ("harmonic", "table", "polydyne")
MODEL_STEP_DEG = 0.5  # a finger's model cam table spacing


def _section(t: Table, units: UnitSystem, element: str, extra: tuple[str, ...] = ()) -> dict[str, Any]:
    """A member's section and material keys from a train table, checked with the train's field names."""
    L = units.length
    kinds = {"diameter": L, "area": f"{L}^2", "inertia": f"{L}^4", "modulus": units.pressure,
             "specific_weight": units.specific_weight, "density": units.density, "mass": units.mass,
             "stiffness": units.stiffness}
    member: dict[str, Any] = {}
    for key, unit in kinds.items():
        if t.has(key):
            member[key] = t.number(key, unit=unit, min_exclusive=0.0, max_value=1e16)
    if t.has("elements"):
        member["elements"] = t.integer("elements", min_value=1, max_value=64)
    has_section = "diameter" in member or "area" in member
    if element == "beam":
        if "stiffness" in member:
            raise InputError(t.field("stiffness"), member["stiffness"], "no stiffness on a beam part (give modulus "
                             "and a section)")
        if "diameter" not in member and not ("area" in member and "inertia" in member):
            raise InputError(t.field("diameter"), None, "a diameter, or an area and an inertia", L)
    elif not has_section and not ("stiffness" in member and "mass" in member):
        raise InputError(t.field("diameter"), None, "a diameter or an area (or a stiffness and a mass)", L)
    if "modulus" not in member and "stiffness" not in member:
        raise InputError(t.field("modulus"), None, "a modulus > 0", units.pressure)
    if not {"specific_weight", "density", "mass"} & set(member):
        raise InputError(t.field("density"), None, "a density, specific_weight or mass > 0", units.density)
    return member


def _part(train: Table, key: str) -> Table:
    """A required part's table (``train.KEY``)."""
    table = train.table(key)
    assert table is not None  # required=True raises when absent
    return table


def _length(t: Table, key: str, units: UnitSystem, default: float | None = None) -> float:
    return t.number(key, unit=units.length, default=default, min_exclusive=0.0, max_value=1e4)


def _angle_scale(t: Table) -> float:
    basis = t.string("angle_basis", default="cam", choices=("cam", "crank"))
    return 0.5 if basis == "crank" else 1.0


def polydyne_table(t: Table, units: UnitSystem) -> tuple[list[float], list[float]]:
    """Angles (cam deg) and lifts of a ``law = "polydyne"`` cam, nose at angle zero."""
    from vtool.presets.ramped_cam import ramped_lift

    scale = _angle_scale(t)
    lift = _length(t, "lift", units)
    ramp = t.number("ramp_height", unit=units.length, min_value=0.0, max_exclusive=lift)
    unit = "cam deg" if scale == 1.0 else "crank deg"
    ramp_deg = scale * t.number("ramp_deg", unit=unit, min_exclusive=0.0, max_value=180.0 / scale)
    flank_deg = scale * t.number("flank_deg", unit=unit, min_exclusive=0.0, max_value=180.0 / scale)
    if ramp_deg + flank_deg >= 180.0:
        raise InputError(t.field("flank_deg"), flank_deg / scale,
                         f"ramp_deg + flank_deg < {180.0 / scale:g} (half a cam turn)", unit)
    nose = t.number("nose_deg", unit="deg", default=0.0, min_value=-360.0, max_value=360.0)
    step = t.number("step_deg", unit="deg", default=MODEL_STEP_DEG, min_value=0.05, max_value=5.0)
    angles = np.arange(0.0, 360.0, step)
    lifts = ramped_lift(angles - nose, lift=lift, ramp_height=ramp, ramp_deg=ramp_deg, flank_deg=flank_deg)
    return angles.tolist(), lifts.tolist()


def _law(t: Table, units: UnitSystem, folder: Path | None) -> dict[str, Any]:
    """The explicit [cam]-style keys of ``[train.cam]`` (law only: no coordinate)."""
    law = t.string("law", choices=LAWS)
    if law == "harmonic":
        doc: dict[str, Any] = {"profile": "harmonic", "amplitude": 0.5 * _length(t, "lift", units)}
        if t.has("offset"):
            doc["offset"] = t.raw("offset")
        t.finish()
        return doc
    if law == "polydyne":
        angles, lifts = polydyne_table(t, units)
        tolerance = t.number("tolerance", unit=units.length, default=1e-4 * max(lifts), min_exclusive=0.0)
        t.finish()
        return {"profile": "table", "angles": angles, "lifts": lifts, "tolerance": tolerance}
    scale = _angle_scale(t)
    if t.has("lift_table"):
        angles, lifts = read_lift_table(t.field("lift_table"), t.string("lift_table"), folder, units.length)
    else:
        angles, lifts = t.numbers("angles", unit="deg"), t.numbers("lifts", unit=units.length)
    doc = {"profile": "table", "angles": [scale * a for a in angles], "lifts": list(lifts)}
    for key in ("harmonics", "tolerance"):
        if t.has(key):
            doc[key] = t.raw(key)
    t.finish()
    return doc


def _follower(train: Table, units: UnitSystem, kind: str | None, required: bool) -> dict[str, Any] | None:
    """``[train.follower]`` (and ``[train.oil]``) as explicit [follower] keys (validated later, named there)."""
    t = train.table("follower", required=required)
    oil = train.table("oil", required=False)
    if t is None:
        if oil is not None:
            raise InputError(train.field("oil"), oil.data, "a [train.follower] beside it (the oil is at its contact)")
        return None
    for key in ("arrangement", "lift", "oil", "roller_arm", "valve_arm", "roller_height", "cam_offset"):
        if t.has(key):
            raise InputError(t.field(key), t.raw(key), "no such field in a train's follower (the type sets it)")
    doc = dict(t.data)
    if kind is not None:
        given = doc.setdefault("kind", kind)
        if given != kind:
            raise InputError(t.field("kind"), given, f'"{kind}" for this train type')
    if oil is not None:
        doc["oil"] = dict(oil.data)
    return doc


def _seat(train: Table, units: UnitSystem, coordinate: int) -> dict[str, Any]:
    t = _part(train, "seat")
    doc: dict[str, Any] = {"coordinate": coordinate, "name": "seat"}
    if t.has("lash") == t.has("position"):
        raise InputError(t.field("lash"), t.raw("lash"), "either lash or position, not both", units.length)
    key = "lash" if t.has("lash") else "position"
    doc[key] = t.number(key, unit=units.length, min_value=-1e4, max_value=1e4)
    t.finish()
    return doc


def _clearance(name: str, ahead: int, behind: int, kind: str) -> dict[str, Any]:
    return {"name": name, "ahead": ahead, "behind": behind, "kind": kind, "state": "enabled", "restitution": 0.0}


def _coordinates(*names: tuple[str, str]) -> list[dict[str, str]]:
    return [{"name": name, "motion": motion} for name, motion in names]


def _member(element: str, length: float, coordinates: list[int], section: dict[str, Any],
            position: tuple[float, float], direction: float) -> dict[str, Any]:
    return {"element": element, "length": length} | section | {
        "coordinates": coordinates, "position": list(position), "direction": direction}


def _initial(doc: dict[str, Any], closed: list[str], preload: float, ratio: float) -> dict[str, Any]:
    given = Table(doc.get("initial", {}), "initial")
    initial: dict[str, Any] = {"closed": closed, "spring_preload": preload, "lever_ratio": ratio}
    if given.has("velocities"):
        initial["velocities"] = given.raw("velocities")
    given.finish()
    return initial


def ohv_pushrod(train: Table, units: UnitSystem, folder: Path | None) -> dict[str, Any]:
    """Gnilka's layout (gnilka-1a's coordinates and members) from its parts."""
    pushrod_t, rocker_t, valve_t = (_part(train, k) for k in ("pushrod", "rocker", "valve"))
    pushrod_length = _length(pushrod_t, "length", units)
    pushrod = _section(pushrod_t, units, "bar")
    cam_arm, valve_arm = _length(rocker_t, "cam_arm", units), _length(rocker_t, "valve_arm", units)
    rocker = _section(rocker_t, units, "beam")
    valve_length = _length(valve_t, "length", units)
    valve = _section(valve_t, units, "bar")
    for t in (pushrod_t, rocker_t, valve_t):
        t.finish()
    tip = cam_arm + valve_arm
    spring = spring_model(_part(train, "spring"), units, 4, 9, (tip + 0.2 * cam_arm, 0.0))
    coordinates = _coordinates(
        ("follower (pushrod lower end)", "translation"), ("left rocker tip", "translation"),
        ("left rocker tip rotation", "rotation"), ("right rocker tip / valve stem top / spring end", "translation"),
        ("right rocker tip rotation", "rotation"), ("rocker pivot rotation", "rotation"), ("valve", "translation"),
        ("pushrod upper end", "translation")) + spring.coordinates
    n = len(coordinates)
    members = {
        "pushrod": _member("bar", pushrod_length, [1, 8], pushrod, (0.0, -pushrod_length), 90.0),
        "left_rocker": _member("beam", cam_arm, [2, 0, 3, 6], rocker, (0.0, 0.0), 0.0),
        "right_rocker": _member("beam", valve_arm, [0, 4, 6, 5], rocker, (cam_arm, 0.0), 0.0),
    } | spring.members | {
        "valve": _member("bar", valve_length, [-7, 4], valve, (tip, -valve_length), 90.0)}
    return {"coordinates": coordinates, "members": members, "cam": n + 1, "seat": n + 2,
            "clearances": [_clearance("cam", 1, n + 1, "external"), _clearance("rocker", 2, 8, "internal"),
                           _clearance("seat", 7, n + 2, "external")] + spring.clearances,
            "closed": ["cam", "rocker"], "preload": spring.preload, "springs": spring.sheets, "ratio": valve_arm / cam_arm,
            "follower_kind": None}


def direct_acting(train: Table, units: UnitSystem, folder: Path | None) -> dict[str, Any]:
    """Bucket on the valve: cam -> bucket (q1) -> stem top / retainer (q2) -> valve head (q3)."""
    bucket_t, valve_t = _part(train, "bucket"), _part(train, "valve")
    bucket = {"mass": bucket_t.number("mass", unit=units.mass, min_exclusive=0.0, max_value=1e9),
              "stiffness": bucket_t.number("stiffness", unit=units.stiffness, min_exclusive=0.0, max_value=1e16)}
    bucket_length = _length(bucket_t, "length", units, default=1.0)
    valve_length = _length(valve_t, "length", units)
    valve = _section(valve_t, units, "bar")
    bucket_t.finish()
    valve_t.finish()
    spring = spring_model(_part(train, "spring"), units, 2, 4, (0.0, -bucket_length))
    coordinates = _coordinates(("bucket (cam contact)", "translation"),
                               ("valve stem top / retainer / spring end", "translation"),
                               ("valve head", "translation")) + spring.coordinates
    n = len(coordinates)
    members = {"bucket": _member("bar", bucket_length, [1, 2], bucket, (0.0, 0.0), -90.0)} | spring.members | {
        "valve": _member("bar", valve_length, [2, 3], valve, (0.0, -bucket_length), -90.0)}
    return {"coordinates": coordinates, "members": members, "cam": n + 1, "seat": n + 2,
            "clearances": [_clearance("cam", 1, n + 1, "external"), _clearance("seat", 3, n + 2, "external")]
            + spring.clearances, "closed": ["cam"], "preload": spring.preload, "springs": spring.sheets, "ratio": 1.0,
            "follower_kind": "flat"}


def hla_pivot(train: Table, units: UnitSystem, length: float) -> tuple[dict[str, Any], dict[str, Any]] | None:
    """``[train.hla]``: the adjuster under a pivot (None without one): the pivot member (the closed chamber's
    stiffness K_oil(p_s) A²/V₀ of the oil alone at the supply pressure, the stiffness the loaded adjuster
    approaches as its air compresses away; the plunger's mass) and the explicit ``[hla]`` table on it
    (:mod:`vtool.presets.hla`)."""
    t = train.table("hla", required=False)
    if t is None:
        return None
    from vtool.presets.hla import read_data
    from vtool.solvers.model.hla import closed_stiffness

    mass = t.number("plunger_mass", unit=units.mass, min_exclusive=0.0, max_value=1e9)
    spec, _, given = read_data(t, units)
    t.finish()
    oil = dataclasses.replace(spec, air_fraction=0.0)
    stiffness = closed_stiffness(oil, spec.supply_pressure) * units.metres_per_length / units.newtons_per_force
    member = {"stiffness": stiffness, "mass": mass}
    return member, {"member": "pivot", "sense": "compression"} | given


def finger_follower(train: Table, units: UnitSystem, folder: Path | None) -> dict[str, Any]:
    """End-pivot roller finger: pivot support, two beams (pivot-roller, roller-pad), valve (module doc)."""
    finger_t, valve_t = _part(train, "finger"), _part(train, "valve")
    geometry = _lever(finger_t, units)
    a, b = geometry["roller_arm"], geometry["valve_arm"]
    finger = _section(finger_t, units, "beam")
    adjuster = hla_pivot(train, units, 0.5 * a)
    if adjuster is not None:
        if train.has("pivot"):
            raise InputError(train.field("pivot"), "given", "no [train.pivot] beside [train.hla] (the adjuster is "
                             "the pivot: its plunger_mass and closed chamber)")
        pivot, pivot_length = adjuster[0], 0.5 * a
    else:
        pivot_t = _part(train, "pivot")
        pivot = {"mass": pivot_t.number("mass", unit=units.mass, min_exclusive=0.0, max_value=1e9),
                 "stiffness": pivot_t.number("stiffness", unit=units.stiffness, min_exclusive=0.0, max_value=1e16)}
        pivot_length = _length(pivot_t, "length", units, default=0.5 * a)
        pivot_t.finish()
    valve_length = _length(valve_t, "length", units)
    valve = _section(valve_t, units, "bar")
    for t in (finger_t, valve_t):
        t.finish()
    spring = spring_model(_part(train, "spring"), units, 7, 9, (b, 0.0))
    coordinates = _coordinates(
        ("finger pivot (lash adjuster)", "translation"), ("finger pivot rotation", "rotation"),
        ("finger at the roller (cam contact)", "translation"), ("finger rotation at the roller", "rotation"),
        ("finger pad", "translation"), ("finger rotation at the pad", "rotation"),
        ("valve tip / retainer / spring end", "translation"), ("valve head", "translation")) + spring.coordinates
    n = len(coordinates)
    members = {
        "pivot": _member("bar", pivot_length, [0, 1], pivot, (0.0, -pivot_length), 90.0),
        "finger_roller_arm": _member("beam", a, [1, 3, 2, 4], finger, (0.0, 0.0), 0.0),
        "finger_valve_arm": _member("beam", b - a, [3, 5, 4, 6], finger, (a, 0.0), 0.0),
    } | spring.members | {"valve": _member("bar", valve_length, [7, 8], valve, (b, 0.0), -90.0)}
    return {"coordinates": coordinates, "members": members, "cam": n + 1, "seat": n + 2,
            "clearances": [_clearance("cam", 3, n + 1, "external"), _clearance("pad", 7, 5, "internal"),
                           _clearance("seat", 8, n + 2, "external")] + spring.clearances,
            "closed": ["cam", "pad"], "preload": spring.preload, "springs": spring.sheets, "ratio": b / a, "follower_kind": "roller",
            "finger": geometry, "arrangement": "finger"} | ({"hla": adjuster[1]} if adjuster is not None else {})


def _lever(t: Table, units: UnitSystem) -> dict[str, float]:
    """A lever's arms and offsets (:class:`vtool.solvers.model.spec.FingerSpec`)."""
    a = _length(t, "roller_arm", units)
    geometry = {"roller_arm": a,
                "valve_arm": t.number("valve_arm", unit=units.length, min_exclusive=a if t.path.endswith("finger")
                                      else 0.0, max_value=1e4)}
    for key in ("roller_height", "cam_offset"):
        if t.has(key):
            geometry[key] = t.number(key, unit=units.length, min_value=-1e4, max_value=1e4)
    return geometry


def centre_pivot_rocker(train: Table, units: UnitSystem, folder: Path | None) -> dict[str, Any]:
    """OHC roller rocker on a shaft (centre pivot): cam under the roller arm, valve under the valve arm.

    Gnilka's rocker without the pushrod: q1 the rocker at the roller (cam contact), the shaft
    grounded, the valve arm's end tied to the valve's top and spring (as gnilka-1a's q4), the valve
    head's coordinate pointing the other way (beta map -q6).
    """
    rocker_t, valve_t = _part(train, "rocker"), _part(train, "valve")
    geometry = _lever(rocker_t, units)
    a, b = geometry["roller_arm"], geometry["valve_arm"]
    rocker = _section(rocker_t, units, "beam")
    valve_length = _length(valve_t, "length", units)
    valve = _section(valve_t, units, "bar")
    rocker_t.finish()
    valve_t.finish()
    spring = spring_model(_part(train, "spring"), units, 4, 7, (a + b, 0.0))
    coordinates = _coordinates(
        ("rocker at the roller (cam contact)", "translation"), ("rocker rotation at the roller", "rotation"),
        ("rocker shaft rotation", "rotation"), ("rocker pad / valve stem top / spring end", "translation"),
        ("rocker rotation at the pad", "rotation"), ("valve head", "translation")) + spring.coordinates
    n = len(coordinates)
    members = {
        "rocker_roller_arm": _member("beam", a, [1, 0, 2, 3], rocker, (0.0, 0.0), 0.0),
        "rocker_valve_arm": _member("beam", b, [0, 4, 3, 5], rocker, (a, 0.0), 0.0),
    } | spring.members | {"valve": _member("bar", valve_length, [-6, 4], valve, (a + b, -valve_length), 90.0)}
    return {"coordinates": coordinates, "members": members, "cam": n + 1, "seat": n + 2,
            "clearances": [_clearance("cam", 1, n + 1, "external"), _clearance("seat", 6, n + 2, "external")]
            + spring.clearances, "closed": ["cam"], "preload": spring.preload, "springs": spring.sheets, "ratio": b / a,
            "follower_kind": "roller", "finger": geometry, "arrangement": "rocker"}


BUILDERS = {OHV_PUSHROD: ohv_pushrod, DIRECT_ACTING: direct_acting, FINGER_FOLLOWER: finger_follower,
            CENTRE_PIVOT_ROCKER: centre_pivot_rocker}


def expand(doc: dict[str, Any], folder: Path | None = None) -> dict[str, Any]:
    """The explicit preset document of a ``[train]`` preset (module doc)."""
    for key in BUILT:
        if key in doc:
            raise InputError(key, "given", "no explicit [" + key + "] beside [train] (the train type builds it; "
                             "`vtool presets expand` prints the explicit form to edit instead)")
    top = Table(doc, "")
    units_name = top.string("units", choices=tuple(UNIT_SYSTEMS))
    units = UNIT_SYSTEMS[units_name]
    train = top.table("train")
    assert train is not None
    kind = train.string("type", choices=TYPES)
    built = BUILDERS[kind](train, units, folder)
    cam_t = _part(train, "cam")
    law = _law(cam_t, units, folder)
    follower = _follower(train, units, built["follower_kind"], required=kind != OHV_PUSHROD)
    seat = _seat(train, units, built["seat"])
    train.finish()
    explicit = {key: value for key, value in doc.items() if key not in ("train", "initial")}
    explicit |= {"coordinates": built["coordinates"], "members": built["members"]}
    cam: dict[str, Any] = {"coordinate": built["cam"], "name": "cam", "offset": law.pop("offset", "static-start")}
    if follower is not None and "finger" in built:
        follower |= {"arrangement": built["arrangement"]} | built["finger"] | {"lift": dict(law)}
        cam |= finger_cam(follower, law, units, folder)
    else:
        cam |= law
        if follower is not None:
            follower["arrangement"] = "translating"
    explicit["cam"] = cam
    explicit["seat"] = seat
    explicit["clearances"] = built["clearances"]
    if built["springs"]:
        explicit["springs"] = built["springs"]
    explicit["initial"] = _initial(doc, built["closed"], built["preload"], built["ratio"])
    if "hla" in built:
        explicit["hla"] = built["hla"]
    if follower is not None:
        explicit["follower"] = follower
    return explicit


def finger_cam(follower: dict[str, Any], law: dict[str, Any], units: UnitSystem,
               folder: Path | None) -> dict[str, Any]:
    """A finger's model cam: the geometric valve lift over the nominal ratio, as a fitted table."""
    from vtool.presets.follower import load_follower
    from vtool.solvers.model.camshape import model_lift

    law_spec = law_spec_of(law, units)
    spec = load_follower(Table(follower, "train.follower"), units, lambda t: law_spec)
    angles = np.arange(0.0, 360.0, MODEL_STEP_DEG)
    lift = model_lift(spec, law_spec, np.radians(angles))
    lift = np.maximum(lift - lift.min(), 0.0)  # the base circle at 0 (the fit's ripple removed)
    tolerance = 1e-4 * float(lift.max())
    return {"profile": "table", "angles": angles.tolist(), "lifts": lift.tolist(), "tolerance": tolerance}


def law_spec_of(law: dict[str, Any], units: UnitSystem) -> Any:
    """The CamSpec of an explicit law dict (checked and fitted as the loader does)."""
    from vtool.solvers.model.cam import fit_table, normalize_table
    from vtool.solvers.model.spec import CamSpec

    if law["profile"] == "harmonic":
        return CamSpec(0, law["amplitude"], None, "lift law")
    theta, lift = normalize_table(law["angles"], law["lifts"], "train.cam", units.length)
    fit_table(theta, lift, law.get("harmonics"), law.get("tolerance"), "train.cam", units.length)
    return CamSpec(0, 0.5 * float(lift.max()), None, "lift law", "table", tuple(theta.tolist()),
                   tuple(lift.tolist()), law.get("harmonics"), law.get("tolerance"))


def train_parameters(doc: dict[str, Any]) -> list[tuple[tuple[str, ...], str]]:
    """(path, unit kind) of every number a train's form may edit: ``("train", "finger", "roller_arm")``."""
    result: list[tuple[tuple[str, ...], str]] = []
    train = doc.get("train", {})
    for part, table in train.items():
        if not isinstance(table, dict):
            continue
        for key, value in table.items():
            if isinstance(value, int | float) and not isinstance(value, bool):
                result.append((("train", part, key), _unit_kind(part, key)))
    return result


def _unit_kind(part: str, key: str) -> str:
    if key in ("mass",):
        return "mass"
    if key in ("stiffness", "rate"):
        return "stiffness"
    if key in ("modulus", "cam_modulus", "follower_modulus"):
        return "pressure"
    if key in ("preload",):
        return "force"
    if key.endswith("_deg") or key in ("angles",):
        return "deg"
    if key in ("density",):
        return "density"
    if key in ("specific_weight",):
        return "specific_weight"
    if key == "area":
        return "area"
    if key == "inertia":
        return "inertia"
    if key in ("elements", "harmonics") or key.endswith("poisson"):
        return ""
    if part == "oil":
        return "mPa*s" if key == "viscosity" else "1/GPa"
    return "length"
