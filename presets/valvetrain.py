"""Valve-train presets: TOML document <-> :class:`vtool.solvers.model.spec.MechanismSpec`.

``load(doc)`` validates every field once, at this boundary, and raises
:class:`vtool.errors.InputError` naming the field, value, allowed range and
unit. ``dump(spec)`` writes the same structure back, so a loaded-then-saved
preset round-trips. See ``presets/gnilka-1a.toml`` for a commented example.

Every number is finite and within a stated physical range (:data:`BOUNDS`,
:data:`RUN_LIMITS`, the counts below), checked before any numerics, so no
preset can reach the solver with values its floating-point arithmetic cannot
carry. The ranges are wide (the same numbers in either unit system) and are
listed in ``docs/limits.md``. The [run] settings are read by one function,
:func:`_run`, whatever gave them: the preset, ``vtool solve``'s ``--rpm``,
``--dt``, ``--degrees`` and ``--backend`` (set into the document by
:func:`with_overrides` before the load), a TUI field, or a study's
:func:`with_run_overrides`.

A missing [damping] section loads with the default (ratio 0.1 on every mode,
factor 1) and a :class:`vtool.errors.PresetWarning` saying so.
"""

from __future__ import annotations

import copy
import dataclasses
import json
import re
import warnings
from dataclasses import replace
from pathlib import Path
from typing import Any

from vtool.errors import InputError, PresetWarning
from vtool.presets.fields import Table
from vtool.presets.lift_table import read_lift_table
from vtool.solvers.backends import DEFAULT, available
from vtool.solvers.model.assembly import split_members, unsplit_members
from vtool.solvers.model.hertz import MIN_RESTITUTION, check_restitution
from vtool.solvers.model.spec import (
    BAR,
    BEAM,
    BETA_RANGE,
    CONTACT_LAWS,
    ELEMENT_SIZE,
    ENABLED,
    EXTERNAL,
    GAMMA_RANGE,
    HERTZ,
    IMPACT_LAWS,
    INTERNAL,
    PINNED,
    REMOVED,
    RIGID,
    START_VELOCITIES,
    CamSpec,
    ClearanceSpec,
    ContactSpec,
    CoordinateSpec,
    DampingSpec,
    InitialSpec,
    LayerDampingSpec,
    MechanismSpec,
    MemberSpec,
    RunSpec,
    SeatSpec,
)
from vtool.solvers.model.units import UNIT_SYSTEMS, UnitSystem

STATIC_START = "static-start"
MAX_DAMPING_RATIO = 1.0
MAX_ELEMENTS = 64

#: Most elastic coordinates, members, clearances (2^n configurations) and extra output quantities.
MAX_COORDINATES = 100
MAX_MEMBERS = 500
MAX_CLEARANCES = 8
MAX_QUANTITIES = 100

#: Physical range of each kind of magnitude, in the preset's unit system (wide enough for both).
BOUNDS: dict[str, tuple[float, float]] = {
    "length": (1e-6, 1e4),
    "area": (1e-12, 1e8),
    "inertia": (1e-24, 1e16),
    "modulus": (1e-3, 1e13),
    "specific_weight": (1e-9, 1e9),
    "density": (1e-12, 1e9),
    "stiffness": (1e-6, 1e13),
    "mass": (1e-15, 1e9),
    "gravity": (1e-3, 1e5),
    "force": (0.0, 1e9),
    "lever_ratio": (1e-3, 1e3),
    "position": (-1e4, 1e4),
    "direction": (-3600.0, 3600.0),
}

#: [run] ranges (and of the --rpm, --dt, --degrees flags): key -> (min, max, unit).
RUN_LIMITS: dict[str, tuple[float, float, str]] = {
    "rpm": (1e-3, 1e6, "rev/min"),
    "degrees": (1e-6, 3.6e6, "deg"),
    "time_step": (1e-12, 1e-1, "s"),
    "output_interval": (1e-6, 3.6e6, "deg"),
}


def load(doc: dict[str, Any], folder: Path | None = None) -> MechanismSpec:
    """Validate a parsed valve-train preset and return its frozen spec.

    ``folder`` resolves a ``[cam] lift_table`` file (default: the working folder).
    """
    train = ""
    if isinstance(doc, dict) and "train" in doc:  # a train type: expanded to the explicit form first
        from vtool.presets.trains import expand

        train = json.dumps(doc["train"])
        doc = expand(doc, folder)
    top = Table(doc, "")
    top.check_unknown(TOP_KEYS)
    top.string("kind", choices=("valvetrain",))
    title = top.string("title", default="")
    notes = top.string("notes", default="", multiline=True)
    units_name = top.string("units", choices=tuple(UNIT_SYSTEMS))
    units = UNIT_SYSTEMS[units_name]
    gravity = _magnitude(top, "gravity", units.acceleration, "gravity", default=units.gravity)

    coordinates = _coordinates(top)
    n = len(coordinates)
    cam = _cam(top.table("cam"), n, units, folder)
    seat_table = top.table("seat", required=False)
    seat = _seat(seat_table, n, cam, units) if seat_table is not None else None
    prescribed = {cam.coordinate} | ({seat.coordinate} if seat else set())
    members = _members(top, n, units)
    clearances = _clearances(top, n, prescribed, cam.coordinate, units)
    names = {c.name: c for c in clearances}
    cam_name = next(c.name for c in clearances if c.behind == cam.coordinate)
    initial = _initial(top.table("initial"), names, cam_name, units)
    damping_table = top.table("damping", required=False)
    if damping_table is None:
        warnings.warn(PresetWarning(
            f"no [damping] section: modal damping ratio {DampingSpec().default_ratio:g} on every mode "
            f"of every contact layer, factor {DampingSpec().factor:g} (add [damping] to choose)"),
            stacklevel=2)
    damping = _damping(damping_table, names)
    contact = _contact(top.table("contact", required=False))
    follower_table = top.table("follower", required=False)
    follower = None
    if follower_table is not None:  # (modules imported only by presets that use them: a sweep loads often)
        from vtool.presets.follower import load_follower
        from vtool.solvers.model.camshape import undercut_warning

        follower = load_follower(follower_table, units, lambda t: _law(t, cam.coordinate, units, folder))

        undercut = undercut_warning(follower, follower.lift or cam)
        if undercut is not None:
            warnings.warn(PresetWarning(undercut), stacklevel=2)
    checks_table = top.table("checks", required=False)
    checks: tuple = ()
    if checks_table is not None:
        from vtool.presets.follower import load_checks

        checks = load_checks(checks_table, units)
    from vtool.presets.springs import load_sheets

    springs = load_sheets(top, units, n)
    hla_table = top.table("hla", required=False)
    hla = None
    if hla_table is not None:
        from vtool.presets.hla import load_hla

        hla = load_hla(hla_table, units, members)
    forces_table = top.table("valve_forces", required=False)
    valve_forces = None
    if forces_table is not None:
        from vtool.presets.valveforces import load_valve_forces

        valve_forces = load_valve_forces(forces_table, units, n)
    run = _run(top.table("run"), _quantity_names(coordinates, cam, seat, clearances), units)
    top.finish()
    spec = MechanismSpec(
        title=title,
        units=units_name,
        gravity=gravity,
        coordinates=coordinates,
        members=members,
        cam=cam,
        seat=seat,
        clearances=clearances,
        initial=initial,
        damping=damping,
        run=run,
        notes=notes,
        contact=contact,
        follower=follower,
        checks=checks,
        springs=springs,
        train=train,
        hla=hla,
        valve_forces=valve_forces,
    )
    spec = split_members(spec)
    if spec.seat is not None and spec.seat.lash is not None:  # the split seat: its coordinate may have moved up
        from vtool.solvers.model.lash import seat_position

        spec = replace(spec, seat=replace(spec.seat, position=float(seat_position(spec, spec.seat.lash))))
    return spec


def _compliance_doc(c: ClearanceSpec) -> dict[str, Any]:
    """The contact keys of a clearance as a preset writes them (none for a rigid one)."""
    if c.rigid:
        return {}
    doc: dict[str, Any] = {"contact": c.contact, "contact_stiffness": c.contact_stiffness}
    if c.contact == HERTZ:
        return doc | {"contact_exponent": c.contact_exponent}
    if c.contact_damping is not None:
        return doc | {"contact_damping": c.contact_damping}
    return doc | {"contact_damping_ratio": c.contact_damping_ratio or 0.0}


def _compliance(t: Table, state: str, units: UnitSystem) -> dict[str, Any]:
    """A clearance's contact law and its spring, dashpot (linear) or exponent (hertz)."""
    contact = t.string("contact", default=RIGID, choices=CONTACT_LAWS)
    keys = ("contact_stiffness", "contact_damping", "contact_damping_ratio", "contact_exponent")
    if contact == RIGID:
        for key in keys:
            if t.raw(key) is not None:
                raise InputError(t.field(key), t.raw(key), 'no value for a rigid contact (set contact = "linear")')
        return {}
    if state != ENABLED:
        raise InputError(t.field("contact"), contact, f"rigid for a {state} clearance")
    if contact == HERTZ:
        stiffness = t.number("contact_stiffness", unit=f"{units.force}/{units.length}^n", required=True,
                             min_value=1e-6, max_value=1e16)
        for key in ("contact_damping", "contact_damping_ratio"):
            if t.raw(key) is not None:
                raise InputError(t.field(key), t.raw(key), "no value for a hertz contact (its Hunt-Crossley "
                                 "damping comes from the restitution)")
        exponent = t.number("contact_exponent", default=1.5, min_value=1.0, max_value=3.0)
        return {"contact": contact, "contact_stiffness": stiffness, "contact_exponent": exponent}
    if t.raw("contact_exponent") is not None:
        raise InputError(t.field("contact_exponent"), t.raw("contact_exponent"), "no value for a linear contact")
    stiffness = _magnitude(t, "contact_stiffness", units.stiffness, "stiffness", required=True)
    result: dict[str, Any] = {"contact": contact, "contact_stiffness": stiffness}
    if t.raw("contact_damping") is not None and t.raw("contact_damping_ratio") is not None:
        raise InputError(t.field("contact_damping"), t.raw("contact_damping"),
                         "contact_damping or contact_damping_ratio, not both")
    if t.raw("contact_damping") is not None:
        result["contact_damping"] = t.number("contact_damping", unit=units.damping, min_value=0.0, max_value=1e12)
    else:
        result["contact_damping_ratio"] = t.number("contact_damping_ratio", default=0.0, min_value=0.0,
                                                   max_value=10.0)
    return result


def _opening(t: Table, behind: int, units: UnitSystem) -> dict[str, Any]:
    """A clearance's ``opening`` and ``sense`` (gap = sense (q[ahead] - q[behind]) + opening; see
    ClearanceSpec): a compliant contact's only, as is the ground (behind = 0)."""
    opening = t.number("opening", unit=units.length, default=0.0, min_value=-1e4, max_value=1e4)
    sense = t.integer("sense", default=1, min_value=-1, max_value=1)
    if sense == 0:
        raise InputError(t.field("sense"), sense, "1 or -1")
    if (opening != 0.0 or sense != 1 or behind == 0) and t.raw("contact") in (None, RIGID):
        key = "opening" if opening != 0.0 else "sense" if sense != 1 else "behind"
        raise InputError(t.field(key), t.raw(key), 'its default for a rigid contact (an opening, sense -1 or the '
                         'ground (behind = 0) need contact = "linear" or "hertz")')
    return ({"opening": opening} if opening else {}) | ({"sense": sense} if sense != 1 else {})


def _contact(t: Table | None) -> ContactSpec:
    """[contact]: the default impact law and the thesis' SCALE (eq. 3.54)."""
    if t is None:
        return ContactSpec()
    impact = t.string("impact", default=ContactSpec.impact, choices=IMPACT_LAWS)
    scale = t.number("rocker_scale", default=1.0, min_value=0.1, max_value=10.0)
    t.finish()
    return ContactSpec(impact, scale)


TOP_KEYS = ("kind", "title", "notes", "units", "gravity", "coordinates", "members", "cam", "seat",
            "clearances", "initial", "contact", "damping", "run", "follower", "checks", "springs", "hla",
            "valve_forces")


def _magnitude(t: Table, key: str, unit: str, what: str, *, default: float | None = None,
               required: bool | None = None) -> float:
    """A number within :data:`BOUNDS` ``[what]`` (``None`` when optional and absent)."""
    low, high = BOUNDS[what]
    return t.number(key, unit=unit, default=default, required=required, min_value=low, max_value=high)


def _count(field: str, items: list[Any] | tuple[Any, ...], most: int, what: str) -> None:
    if len(items) > most:
        raise InputError(field, f"{len(items)} {what}", f"at most {most} {what}")


def _coordinates(top: Table) -> tuple[CoordinateSpec, ...]:
    tables = top.array_of_tables("coordinates")
    if not tables:
        raise InputError("coordinates", [], "at least one [[coordinates]] entry")
    _count("coordinates", tables, MAX_COORDINATES, "coordinates")
    result: list[CoordinateSpec] = []
    for number, t in enumerate(tables, start=1):
        name = t.string("name")
        motion = t.string("motion", choices=("translation", "rotation"))
        t.finish()
        result.append(CoordinateSpec(number, name, motion))
    return tuple(result)


def _coordinate_ref(t: Table, key: str, allowed: set[int], what: str) -> int:
    value = t.integer(key)
    if value not in allowed:
        raise InputError(t.field(key), value, f"one of the {what}: {sorted(allowed)}")
    return value


def _cam(t: Table, n: int, units: UnitSystem, folder: Path | None = None) -> CamSpec:
    coordinate = t.integer("coordinate", min_value=n + 1, max_value=n + 2)
    name = t.string("name", default="cam")
    profile = t.string("profile", default="harmonic", choices=("harmonic", "table"))
    table: dict[str, Any] = {}
    if profile == "table":
        table = _cam_table(t, units, folder)
        amplitude = 0.5 * max(table["lifts"])
    else:
        amplitude = _magnitude(t, "amplitude", units.length, "length")
    raw_offset = t.raw("offset", STATIC_START)
    if raw_offset == STATIC_START:
        offset = None
    elif isinstance(raw_offset, int | float) and not isinstance(raw_offset, bool):
        # the static start puts the follower on the cam with force k_eff * offset: a negative
        # offset would start with the cam contact in tension
        offset = t.number("offset", unit=units.length, min_value=0.0, max_value=BOUNDS["length"][1])
    else:
        raise InputError(t.field("offset"), raw_offset, f'"{STATIC_START}" or a number', units.length)
    if table and offset is not None:
        raise InputError(t.field("offset"), offset, f'"{STATIC_START}" for a table cam (its base circle carries '
                         f"the spring preload)", units.length)
    t.finish()
    return CamSpec(coordinate, amplitude, offset, name, profile, **table)


def _law(t: Table, coordinate: int, units: UnitSystem, folder: Path | None) -> CamSpec:
    """A lift law given as a [cam]-like table without its coordinate ([follower.lift])."""
    profile = t.string("profile", default="harmonic", choices=("harmonic", "table"))
    table = _cam_table(t, units, folder) if profile == "table" else {}
    amplitude = 0.5 * max(table["lifts"]) if table else _magnitude(t, "amplitude", units.length, "length")
    t.finish()
    return CamSpec(coordinate, amplitude, None, "lift law", profile, **table)


def _law_doc(cam: CamSpec) -> dict[str, Any]:
    """The lift-law keys of a cam (inverse of :func:`_law`; [cam] adds its coordinate, name and offset)."""
    if cam.profile == "harmonic":
        return {"profile": cam.profile, "amplitude": cam.amplitude}
    # inline, so a saved copy does not depend on the table file's folder
    return {"profile": cam.profile, "angles": list(cam.angles), "lifts": list(cam.lifts)} | (
        {"harmonics": cam.harmonics} if cam.harmonics else {"tolerance": cam.tolerance})


def _cam_table(t: Table, units: UnitSystem, folder: Path | None) -> dict[str, Any]:
    """A lift table (file or inline arrays) and its fit setting; see solvers/model/cam.py."""
    from vtool.solvers.model.cam import fit_table, junction_warning, normalize_table

    lift_table = t.string("lift_table", default="") or None
    polyline = t.string("polyline", default="") or None  # a measured scan (presets/cam_scan.py)
    if lift_table is not None and polyline is not None:
        raise InputError(t.field("polyline"), polyline, "either lift_table or polyline, not both")
    if lift_table is not None or polyline is not None:
        if t.has("angles") or t.has("lifts"):
            raise InputError(t.field("angles"), t.raw("angles"), "no inline table beside lift_table")
        if lift_table is not None:
            angles, lifts = read_lift_table(t.field("lift_table"), lift_table, folder, units.length)
        else:
            from vtool.presets.cam_scan import read_polyline

            angles, lifts = read_polyline(t.field("polyline"), polyline, folder)  # type: ignore[arg-type]  # a polyline here: lift_table and polyline are exclusive (checked above)
    else:
        angles = t.numbers("angles", unit="deg")
        lifts = t.numbers("lifts", unit=units.length)
    scan = t.table("scan", required=False)
    smoothed_harmonics = None
    if scan is not None:  # units, angle, tappet/valve, smoothing of a measured scan
        from vtool.presets.cam_scan import from_table

        measured = from_table(scan, angles, lifts, units, t.path)
        angles, lifts = measured.angles.tolist(), measured.lifts.tolist()
        smoothed_harmonics = None if measured.smoothed is None else measured.smoothed.harmonics
    theta, lift = normalize_table(angles, lifts, t.path, units.length)
    if lift.min() < 0.0 or lift.max() <= 0.0:
        raise InputError(t.field("lifts"), float(lift.min()), "lifts >= 0 (0 = base circle), not all 0", units.length)
    harmonics = t.integer("harmonics", default=0, min_value=0) or None
    tolerance = t.number("tolerance", unit=units.length, required=False, min_exclusive=0.0)
    if smoothed_harmonics is not None and harmonics is None and tolerance is None:
        harmonics = smoothed_harmonics  # a smoothed scan is a series of this many harmonics
    if (harmonics is None) == (tolerance is None):
        raise InputError(t.field("harmonics"), harmonics, "either harmonics (>= 1) or tolerance, not both")
    fit_table(theta, lift, harmonics, tolerance, t.path, units.length)  # refuse a table that cannot be fitted
    # a smoothed scan is a band-limited series (its base circle clipped at 0 by the noise, said in its note)
    jumps = None if smoothed_harmonics is not None else junction_warning(theta, lift, t.path)
    if jumps is not None:
        warnings.warn(PresetWarning(jumps), stacklevel=3)
    return dict(angles=tuple(theta.tolist()), lifts=tuple(lift.tolist()), harmonics=harmonics,
                tolerance=tolerance, lift_table=lift_table or polyline)


def _seat(t: Table, n: int, cam: CamSpec, units: UnitSystem) -> SeatSpec:
    coordinate = t.integer("coordinate", min_value=n + 1, max_value=n + 2)
    if coordinate == cam.coordinate:
        raise InputError(t.field("coordinate"), coordinate, f"a number other than the cam's ({cam.coordinate})")
    name = t.string("name", default="seat")
    # a negative lash would be an interference: the valve held off its seat on the base circle
    lash = t.number("lash", unit=units.length, required=False, min_value=0.0)
    if (lash is not None) == t.has("position"):
        raise InputError(t.field("position"), t.raw("position"), "either position or lash, not both", units.length)
    low, high = BOUNDS["position"]
    position = 0.0 if lash is not None else t.number("position", unit=units.length, min_value=low, max_value=high)
    t.finish()
    return SeatSpec(coordinate, position, name, lash)


def _members(top: Table, n: int, units: UnitSystem) -> tuple[MemberSpec, ...]:
    members = []
    for name, t in top.tables("members"):
        element = t.string("element", choices=(BAR, BEAM))
        length = _magnitude(t, "length", units.length, "length")
        coords = t.raw("coordinates")
        size = ELEMENT_SIZE[element]
        valid = (
            isinstance(coords, list)
            and len(coords) == size
            and all(isinstance(c, int) and not isinstance(c, bool) and abs(c) <= n for c in coords)
        )
        if not valid:
            raise InputError(
                t.field("coordinates"), coords,
                f"{size} signed coordinate numbers, each in -{n}..{n} (0 = ground)",
            )
        diameter = _magnitude(t, "diameter", units.length, "length", required=False)
        area = _magnitude(t, "area", f"{units.length}^2", "area", required=False)
        inertia = _magnitude(t, "inertia", f"{units.length}^4", "inertia", required=False)
        modulus = _magnitude(t, "modulus", units.pressure, "modulus", required=False)
        specific_weight = _magnitude(t, "specific_weight", units.specific_weight, "specific_weight",
                                     required=False)
        density = _magnitude(t, "density", units.density, "density", required=False)
        stiffness = _magnitude(t, "stiffness", units.stiffness, "stiffness", required=False)
        mass = _magnitude(t, "mass", units.mass, "mass", required=False)
        position = None
        if t.has("position"):
            raw = t.numbers("position", unit=units.length)
            low, high = BOUNDS["position"]
            if len(raw) != 2 or not all(low <= v <= high for v in raw):
                raise InputError(t.field("position"), raw, f"two numbers [x, y], each in {low:g}..{high:g}",
                                 units.length)
            position = (raw[0], raw[1])
        low, high = BOUNDS["direction"]
        direction = t.number("direction", unit="deg", default=0.0, min_value=low, max_value=high)
        elements = t.integer("elements", default=1, min_value=1, max_value=MAX_ELEMENTS)
        t.finish()
        where = t.path
        if element == BEAM and stiffness is not None:
            raise InputError(f"{where}.stiffness", stiffness, "no explicit stiffness on a beam (give modulus and section)")
        if diameter is None and area is None and (mass is None or (element == BAR and stiffness is None)):
            raise InputError(f"{where}.diameter", None, "a diameter or an area", units.length)
        if element == BEAM and diameter is None and inertia is None:
            raise InputError(f"{where}.inertia", None, "an inertia (or a diameter) for a beam", f"{units.length}^4")
        if modulus is None and not (element == BAR and stiffness is not None):
            raise InputError(f"{where}.modulus", None, "a modulus > 0", units.pressure)
        if mass is None and specific_weight is None and density is None:
            raise InputError(f"{where}.specific_weight", None, "a specific_weight, density or mass > 0", units.specific_weight)
        members.append(
            MemberSpec(name, element, length, tuple(coords), modulus, diameter, area, inertia,
                       specific_weight, density, stiffness, mass, position, direction, elements)
        )
    if not members:
        raise InputError("members", {}, "at least one [members.NAME] table")
    _count("members", members, MAX_MEMBERS, "members")
    used = {abs(c) for m in members for c in m.coordinates if c}
    for number in range(1, n + 1):
        if number not in used:
            raise InputError("coordinates", number, "every coordinate used by at least one member")
    return tuple(members)


def _clearances(top: Table, n: int, prescribed: set[int], cam_coordinate: int,
                units: UnitSystem) -> tuple[ClearanceSpec, ...]:
    result: list[ClearanceSpec] = []
    elastic = set(range(1, n + 1))
    tables = top.array_of_tables("clearances")
    _count("clearances", tables, MAX_CLEARANCES, "clearances (2^n configurations)")
    for t in tables:
        name = t.string("name")
        if any(c.name == name for c in result):
            raise InputError(t.field("name"), name, "a name not used by another clearance")
        kind = t.string("kind", choices=(EXTERNAL, INTERNAL))
        ahead = _coordinate_ref(t, "ahead", elastic, "elastic coordinates")
        if kind == EXTERNAL:
            behind = _coordinate_ref(t, "behind", prescribed | {0}, "prescribed coordinates (cam, seat) or 0 (ground)")
        else:
            behind = _coordinate_ref(t, "behind", elastic - {ahead}, "other elastic coordinates")
        state = t.string("state", default=ENABLED, choices=(ENABLED, PINNED, REMOVED))
        if state == PINNED and kind == EXTERNAL:
            raise InputError(t.field("state"), state, "enabled or removed for an external clearance")
        restitution = t.number("restitution", default=0.0, min_value=0.0, max_value=1.0)
        impact = t.string("impact", choices=IMPACT_LAWS) if t.raw("impact") is not None else None
        contact = _compliance(t, state, units) | _opening(t, behind, units)
        if contact.get("contact") == HERTZ and not check_restitution(restitution):
            raise InputError(t.field("restitution"), restitution,
                             f">= {MIN_RESTITUTION} and <= 1 for a hertz contact (Hunt-Crossley damping gives e = 0 "
                             f"only at infinite damping; a rigid contact takes 0)")
        t.finish()
        result.append(ClearanceSpec(name, ahead, behind, kind, state, restitution, impact, **contact))
    if sum(c.behind == cam_coordinate for c in result) != 1:
        raise InputError("clearances", [c.name for c in result], f"exactly one clearance with behind = {cam_coordinate} (the cam)")
    return tuple(result)


def _initial(t: Table, names: dict[str, ClearanceSpec], cam_name: str, units: UnitSystem) -> InitialSpec:
    closed = _names(t, "closed", names)
    for name in closed:
        if names[name].state == REMOVED:
            raise InputError(t.field("closed"), name, "clearances that are not removed")
        if names[name].contact == HERTZ:
            raise InputError(t.field("closed"), name, "clearances with a rigid or linear contact (a hertz "
                             "contact starts open: its static overlap is not linear)")
        if names[name].kind == EXTERNAL and name != cam_name:
            # the static start loads the mechanism at the follower only; it cannot put the valve on its seat
            raise InputError(t.field("closed"), name, f"only the cam clearance ('{cam_name}') and internal clearances")
    preload = _magnitude(t, "spring_preload", units.force, "force")
    ratio = _magnitude(t, "lever_ratio", "", "lever_ratio")
    velocities = t.string("velocities", default=InitialSpec.velocities, choices=START_VELOCITIES)
    t.finish()
    return InitialSpec(closed, preload, ratio, velocities)


def _names(t: Table, key: str, names: dict[str, ClearanceSpec], kinds: tuple[str, ...] = (EXTERNAL, INTERNAL)) -> tuple[str, ...]:
    value = t.raw(key, None)
    allowed = [n for n, c in names.items() if c.kind in kinds]
    if not isinstance(value, list) or any(not isinstance(v, str) or v not in allowed for v in value):
        raise InputError(t.field(key), value, f"a list of clearance names from: {', '.join(allowed)}")
    return tuple(value)


def _ratio(t: Table, key: str, default: float | None = None) -> float:
    return t.number(key, default=default, min_value=0.0, max_value=MAX_DAMPING_RATIO)


def _damping(t: Table | None, names: dict[str, ClearanceSpec]) -> DampingSpec:
    if t is None:
        return DampingSpec()
    factor = t.number("factor", default=1.0, min_value=0.0, max_value=1e6)
    default_ratio = _ratio(t, "default_ratio", 0.1)
    layers: list[LayerDampingSpec] = []
    for lt in t.array_of_tables("layers", required=False):
        closed = _names(lt, "closed", names, (INTERNAL,))
        ratio = _ratio(lt, "default_ratio", default_ratio)
        overrides = []
        mt = lt.table("mode_ratios", required=False)
        if mt is not None:
            for key in list(mt.data):
                if not (key.isdigit() and len(key) <= 3 and 1 <= int(key) <= MAX_COORDINATES):
                    raise InputError(mt.field(key), key, "a mode number 1, 2, ... (ascending frequency)")
                overrides.append((int(key), _ratio(mt, key)))
            mt.finish()
        lt.finish()
        if any(set(layer.closed) == set(closed) for layer in layers):
            raise InputError(lt.field("closed"), list(closed),
                             "a set of closed clearances no other [[damping.layers]] entry names")
        layers.append(LayerDampingSpec(tuple(sorted(set(closed))), ratio, tuple(sorted(overrides))))
    t.finish()
    largest = max([default_ratio] + [lay.default_ratio for lay in layers]
                  + [r for lay in layers for _, r in lay.mode_ratios])
    if largest > 0 and factor * largest > MAX_DAMPING_RATIO:
        raise InputError("damping.factor", factor,
                         f"<= {MAX_DAMPING_RATIO / largest:.6g} (factor x largest ratio {largest:g} must be <= 1)")
    return DampingSpec(factor, default_ratio, tuple(layers))


def _quantity_names(coordinates, cam, seat, clearances) -> tuple[set[int], set[int]]:
    numbers = {c.number for c in coordinates} | {cam.coordinate} | ({seat.coordinate} if seat else set())
    return numbers, {c.ahead for c in clearances}


QUANTITY = re.compile(r"q(\d+)(?:-q(\d+))?|F(\d+)")


def _quantities(t: Table, numbers: set[int], forces: set[int], key: str = "quantities") -> tuple[str, ...]:
    value = t.raw(key, [])
    expected = (f"a list of 'q<i>', 'q<i>-q<j>' (i, j in {sorted(numbers)}) or 'F<i>' "
                f"(i in {sorted(forces)})")
    if not isinstance(value, list):
        raise InputError(t.field(key), value, expected)
    _count(t.field(key), value, MAX_QUANTITIES, "quantities")
    for item in value:
        match = QUANTITY.fullmatch(item) if isinstance(item, str) else None
        ok = match is not None and (
            (match[3] is not None and int(match[3]) in forces)
            or (match[1] is not None and int(match[1]) in numbers and (match[2] is None or int(match[2]) in numbers))
        )
        if not ok:
            raise InputError(t.field(key), item, expected)
    return tuple(value)


RUN_KEYS = ("rpm", "degrees", "time_step", "backend", "output_interval", "beta", "gamma", "quantities",
            "cycles", "steady", "jump_angle", "jump_gap", "bounce_lift", "orders", "highest_order")
#: [run] cycle-by-cycle and criteria ranges: key -> (min, max, unit)
CYCLE_LIMITS: dict[str, tuple[float, float, str]] = {
    "cycles": (1, 10_000, "cam cycles"),
    "max_cycles": (2, 10_000, "cam cycles"),
    "tolerance": (1e-12, 1.0, "(relative change per cycle)"),
    "jump_angle": (0.0, 360.0, "deg"),
    "highest_order": (1, 1000, "cam orders"),
}


def _cycles(t: Table, units: Any) -> dict[str, Any]:
    """run.cycles, run.steady = { tolerance, max_cycles } and the speed criteria (vtool.solvers.studies.steady,
    vtool.solvers.studies.metrics); run.steady = {} takes the defaults."""
    from vtool.solvers.studies.steady import DEFAULT_MAX_CYCLES, DEFAULT_TOLERANCE

    def integer(table: Table, key: str, default: int) -> int:
        low, high, _ = CYCLE_LIMITS[key]
        return table.integer(key, default=default, min_value=int(low), max_value=int(high)) if table.has(key) \
            else default

    values: dict[str, Any] = {"cycles": integer(t, "cycles", 0)}
    steady = t.table("steady", required=False)
    if steady is not None:
        if values["cycles"]:
            raise InputError("run.steady", "with run.cycles", "one of run.cycles (a fixed count) or run.steady")
        low, high, unit = CYCLE_LIMITS["tolerance"]
        values["steady_tolerance"] = steady.number("tolerance", default=DEFAULT_TOLERANCE, min_value=low,
                                                   max_value=high)
        values["steady_max_cycles"] = integer(steady, "max_cycles", DEFAULT_MAX_CYCLES)
        steady.finish()
    low, high, unit = CYCLE_LIMITS["jump_angle"]
    values["jump_angle"] = t.number("jump_angle", unit=unit, default=1.0, min_value=low, max_value=high)
    for key in ("jump_gap", "bounce_lift"):
        if t.has(key):
            values[key] = t.number(key, unit=units.length, min_value=0.0, max_value=1e4)
    return values


def _run(t: Table, names: tuple[set[int], set[int]], units: Any) -> RunSpec:
    """The [run] table: every value checked here, once (ranges :data:`RUN_LIMITS`, Newmark's
    ``BETA_RANGE``/``GAMMA_RANGE``, the installed back ends); below the loader a RunSpec is trusted."""
    t.check_unknown(RUN_KEYS)
    def limited(key: str, default: float | None = None) -> float:
        low, high, unit = RUN_LIMITS[key]
        return t.number(key, unit=unit, default=default, min_value=low, max_value=high)

    rpm = limited("rpm")
    degrees = limited("degrees")
    time_step = limited("time_step")
    backend = t.string("backend", default=DEFAULT, choices=tuple(available()))
    output_interval = limited("output_interval", 1.0)
    beta = t.number("beta", default=1.0 / 6.0, min_exclusive=BETA_RANGE[0], max_value=BETA_RANGE[1])
    gamma = t.number("gamma", default=0.5, min_value=GAMMA_RANGE[0], max_value=GAMMA_RANGE[1])
    quantities = _quantities(t, *names)
    cycles = _cycles(t, units)
    cycles["orders"] = _quantities(t, *names, key="orders")
    low, high, _ = CYCLE_LIMITS["highest_order"]
    cycles["highest_order"] = t.integer("highest_order", default=24, min_value=int(low), max_value=int(high))
    t.finish()
    return RunSpec(rpm, degrees, time_step, backend, output_interval, beta, gamma, quantities, **cycles)


def dump(spec: MechanismSpec) -> dict[str, Any]:
    """The preset document for a spec (inverse of :func:`load`); a spec entered by train type dumps as its
    [train] while its model is what the type gives (:func:`train_document`)."""
    given, spec = spec, unsplit_members(spec)
    doc: dict[str, Any] = {"kind": "valvetrain", "title": spec.title}
    if spec.notes:
        doc["notes"] = spec.notes
    doc["units"] = spec.units
    doc["gravity"] = spec.gravity
    doc["coordinates"] = [{"name": c.name, "motion": c.motion} for c in spec.coordinates]
    members: dict[str, Any] = {}
    for m in spec.members:
        entry: dict[str, Any] = {"element": m.element, "length": m.length}
        for key in ("diameter", "area", "inertia", "modulus", "specific_weight", "density", "stiffness", "mass"):
            value = getattr(m, key)
            if value is not None:
                entry[key] = value
        entry["coordinates"] = list(m.coordinates)
        if m.position is not None:
            entry["position"] = list(m.position)
            entry["direction"] = m.direction
        if m.elements > 1:
            entry["elements"] = m.elements
        members[m.name] = entry
    doc["members"] = members
    cam = spec.cam
    doc["cam"] = {"coordinate": cam.coordinate, "name": cam.name, "profile": cam.profile,
                  "offset": STATIC_START if cam.offset is None else cam.offset} | _law_doc(cam)
    if spec.seat is not None:
        seat = spec.seat
        doc["seat"] = {"coordinate": seat.coordinate, "name": seat.name}
        doc["seat"].update({"position": seat.position} if seat.lash is None else {"lash": seat.lash})
    doc["clearances"] = [
        {"name": c.name, "ahead": c.ahead, "behind": c.behind, "kind": c.kind,
         "state": c.state, "restitution": c.restitution} | ({"impact": c.impact} if c.impact else {})
        | _compliance_doc(c) | ({"opening": c.opening} if c.opening else {}) | ({"sense": c.sense} if c.sense != 1 else {})
        for c in spec.clearances
    ]
    doc["initial"] = {
        "closed": list(spec.initial.closed),
        "spring_preload": spec.initial.spring_preload,
        "lever_ratio": spec.initial.lever_ratio,
        "velocities": spec.initial.velocities,
    }
    doc["contact"] = {"impact": spec.contact.impact, "rocker_scale": spec.contact.rocker_scale}
    damping: dict[str, Any] = {"factor": spec.damping.factor, "default_ratio": spec.damping.default_ratio}
    layers: list[dict[str, Any]] = []
    for layer in spec.damping.layers:
        entry = {"closed": list(layer.closed), "default_ratio": layer.default_ratio}
        if layer.mode_ratios:
            entry["mode_ratios"] = {str(k): v for k, v in layer.mode_ratios}
        layers.append(entry)
    if layers:
        damping["layers"] = layers
    doc["damping"] = damping
    r = spec.run
    doc["run"] = _dump_run(r)
    if spec.follower is not None:
        from vtool.presets.follower import dump_follower

        doc["follower"] = dump_follower(spec.follower, _law_doc)
    if spec.checks:
        doc["checks"] = {c.name: c.limit for c in spec.checks}
    if spec.springs:
        from vtool.presets.springs import sheet_document

        doc["springs"] = [sheet_document(s) for s in spec.springs]
    if spec.hla is not None:
        from vtool.presets.hla import dump_hla

        doc["hla"] = dump_hla(spec.hla)
    if spec.valve_forces is not None:
        from vtool.presets.valveforces import dump_valve_forces

        doc["valve_forces"] = dump_valve_forces(spec.valve_forces)
    return train_document(given, doc) or doc


TRAIN_KEEPS = ("kind", "title", "notes", "units", "gravity", "contact", "damping", "run", "checks", "valve_forces")


def train_document(spec: MechanismSpec, explicit: dict[str, Any]) -> dict[str, Any] | None:
    """The train-type document of a spec entered by type, while its model is still what the type gives
    (else None: the explicit form, e.g. after a member was split or a clearance pinned)."""
    if not spec.train:
        return None
    doc = {key: explicit[key] for key in TRAIN_KEEPS if key in explicit}
    doc["train"] = json.loads(spec.train)
    doc["initial"] = {"velocities": spec.initial.velocities}
    try:
        again = load(copy.deepcopy(doc))
    except InputError:  # e.g. a lift_table file the saved copy's folder does not hold
        return None
    return doc if again == spec else None


def _dump_run(r: RunSpec) -> dict[str, Any]:
    run: dict[str, Any] = {"rpm": r.rpm, "degrees": r.degrees, "time_step": r.time_step, "backend": r.backend,
                           "output_interval": r.output_interval, "beta": r.beta, "gamma": r.gamma}
    if r.quantities:
        run["quantities"] = list(r.quantities)
    if r.cycles:
        run["cycles"] = r.cycles
    if r.steady_tolerance:
        run["steady"] = {"tolerance": r.steady_tolerance, "max_cycles": r.steady_max_cycles}
    if r.jump_angle != 1.0:
        run["jump_angle"] = r.jump_angle
    for key in ("jump_gap", "bounce_lift"):
        if getattr(r, key) is not None:
            run[key] = getattr(r, key)
    if r.orders:
        run["orders"] = list(r.orders)
    if r.highest_order != 24:
        run["highest_order"] = r.highest_order
    return run


RPM_IN_TITLE = re.compile(r"\b\d{1,3}(?:,\d{3})*(?:\.\d+)?\s*RPM\b|\b\d+(?:\.\d+)?\s*RPM\b", re.IGNORECASE)


def rpm_title(title: str, rpm: float) -> str:
    """The title with its speed replaced by ``rpm`` and marked ``(override)``, or the speed appended."""
    speed = f"{rpm:,.0f}" if rpm >= 10 and float(rpm).is_integer() else f"{rpm:,.6g}"
    text = f"{speed} RPM (override)"
    if RPM_IN_TITLE.search(title):
        return RPM_IN_TITLE.sub(text, title, count=1)
    return f"{title} at {text}" if title else f"at {text}"


def with_run_overrides(spec: MechanismSpec, **changes: Any) -> MechanismSpec:
    """The spec with some [run] settings changed, read by the loader's own [run] reader (:func:`_run`).

    ``changes`` uses the preset's [run] keys (rpm, degrees, time_step, backend,
    output_interval, beta, gamma); ``None`` values are ignored. A changed speed
    is written into the title ("... 10,500 RPM (override) ...").
    """
    given = {key: value for key, value in changes.items() if value is not None}
    unknown = sorted(set(given) - set(RUN_KEYS))
    if unknown:
        raise InputError(f"run.{unknown[0]}", given[unknown[0]], f"one of: {', '.join(RUN_KEYS)}")
    names = _quantity_names(spec.coordinates, spec.cam, spec.seat, spec.clearances)
    table = _dump_run(spec.run) | given
    if "quantities" not in given:  # (checked at the load against the preset's own numbering, which a train's
        table.pop("quantities", None)  # expansion and the members' split renumber: kept as loaded)
    run = _run(Table(table, "run"), names, spec.unit_system)
    if "quantities" not in given:
        run = dataclasses.replace(run, quantities=spec.run.quantities)
    title = spec.title
    if "rpm" in given and run.rpm != spec.run.rpm:
        title = rpm_title(title, run.rpm)
    return dataclasses.replace(spec, run=run, title=title)


def with_overrides(doc: dict[str, Any], overrides: dict[str, Any]) -> dict[str, Any]:
    """The preset document with values given outside it (``vtool solve``'s flags, by field path:
    ``run.rpm``, ``contact.impact``, ...) set, for the loader to check once like any other field. An impact
    law for the mechanism (``contact.impact``) applies to every clearance, dropping their own; a changed
    speed is written into the title as :func:`with_run_overrides` does."""
    result = copy.deepcopy(doc)
    for path, value in overrides.items():
        table, _, key = path.rpartition(".")
        if not isinstance(result.get(table), dict):
            result[table] = {}
        result[table][key] = value
    if "contact.impact" in overrides:
        for clearance in result.get("clearances", []):
            if isinstance(clearance, dict):
                clearance.pop("impact", None)
    rpm = overrides.get("run.rpm")
    if rpm is not None and isinstance(result.get("title", ""), str) and rpm != doc.get("run", {}).get("rpm"):
        result["title"] = rpm_title(result.get("title", ""), float(rpm))
    return result
