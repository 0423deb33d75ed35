"""The valve spring of a train type (``[train.spring]``), expanded into explicit model parts.

:func:`spring_model` is the one boundary between a train type
(:mod:`vtool.presets.trains`) and its spring: the train passes the spring's
table, the unit system, the elastic coordinate the spring's moving end sits
on (the retainer) and the number the spring's own new coordinates would
start at; it gets back a :class:`SpringModel`: the members (explicit
``[members.NAME]`` tables), coordinates and clearances to add, the installed
preload (the force with the valve closed) and the spring's rate. The train
appends the coordinates after its own and numbers the cam and seat after
all of them, so a spring with internal masses (a later data-sheet spring:
coils, pitch, force-length table, coil clash as clearances, nested springs)
is a change of this module only.

Today's spring (``[train.spring]``)::

    rate = 30.0            # force/length
    preload = 250.0        # force at the installed length; or installed_length and free_length
    mass = 4.0e-5          # the spring's own mass (mass unit); a third of it moves with the retainer
    length = 40.0          # installed length (drawing, and with free_length the preload)
    elements = 2           # equal bar elements (surge modes; 1 = one bar)

It becomes one elastic bar from the ground (the cylinder head) to the
retainer's coordinate with that stiffness and mass (consistent mass: the
retainer sees m/3 of it), split into ``elements`` equal elements.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from vtool.errors import InputError
from vtool.presets.fields import Table
from vtool.solvers.model.spring import (
    SHEAR_RATIO,
    STRENGTH_MATERIALS,
    SpringSpec,
    closing_forces,
    fitted_strength_law,
    power_law_strength,
    segment_rates,
)
from vtool.units import UnitSystem

MAX_ELEMENTS = 64
SPRING_KEYS = ("rate", "preload", "mass", "length", "free_length", "installed_length", "elements")
SHEET_KEYS = ("wire_diameter", "coil_diameter", "active_coils", "total_coils", "free_length", "installed_length",
              "shear_modulus", "density", "tensile_strength", "fatigue_limit", "solid_length", "shear_ratio",
              "segment_coils", "segment_pitches", "lengths", "forces", "elements", "inner", "coil_contact", "wire_height",
              "block_stiffness", "block_damping_ratio")
#: A closed pitch segment's block stiffness, as a multiple of the segment's own coil rate k_i, and its
#: dashpot as a ratio of critical on the local masses: our stand-ins (no measured block stiffness in our
#: sources), chosen so that a closed segment is 100 times stiffer than while open (the static force-length
#: curve then follows the pitch diagram's to within the closed segments' 1/(101 k_i)) and a coil clash
#: rebounds with e = exp(-pi zeta / sqrt(1 - zeta^2)) = 0.73 for a lone mass. A data sheet's
#: ``block_stiffness`` (force/length) and ``block_damping_ratio`` replace them.
BLOCK_FACTOR = 100.0
BLOCK_DAMPING_RATIO = 0.1


@dataclass(frozen=True)
class SpringModel:
    """What a spring adds to the explicit model (see the module doc)."""

    members: dict[str, dict[str, Any]]
    preload: float
    rate: float
    coordinates: list[dict[str, Any]] = field(default_factory=list)
    clearances: list[dict[str, Any]] = field(default_factory=list)
    sheets: list[dict[str, Any]] = field(default_factory=list)  # data sheets: the explicit form's [[springs]]


def spring_model(t: Table, units: UnitSystem, end: int, first_new: int,
                 position: tuple[float, float] = (0.0, 0.0)) -> SpringModel:
    """The valve spring of ``[train.spring]`` acting between the ground and coordinate ``end``.

    ``first_new`` is the number the spring's own coordinates would take (none today);
    ``position`` places the spring's fixed end in drawings.
    """
    if t.has("wire_diameter"):
        return sheet_spring_model(t, units, end, first_new, position)
    L = units.length
    rate = t.number("rate", unit=units.stiffness, min_exclusive=0.0, max_value=1e13)
    mass = t.number("mass", unit=units.mass, min_exclusive=0.0, max_value=1e9)
    installed = t.number("installed_length", unit=L, required=False, min_exclusive=0.0, max_value=1e4)
    free = t.number("free_length", unit=L, required=False, min_exclusive=0.0, max_value=1e4)
    if t.has("preload") == (free is not None):
        raise InputError(t.field("preload"), t.raw("preload"),
                         "either preload or free_length (with installed_length), not both", units.force)
    if free is not None:
        if installed is None:
            raise InputError(t.field("installed_length"), None, "a value with free_length", L)
        if free <= installed:
            raise InputError(t.field("free_length"), free, f"> installed_length ({installed:g})", L)
        preload = rate * (free - installed)
    else:
        preload = t.number("preload", unit=units.force, min_value=0.0, max_value=1e9)
    length = t.number("length", unit=L, default=installed if installed is not None else 1.0,
                      min_exclusive=0.0, max_value=1e4)
    elements = t.integer("elements", default=1, min_value=1, max_value=MAX_ELEMENTS)
    t.finish()
    member: dict[str, Any] = {"element": "bar", "length": length, "stiffness": rate, "mass": mass,
                              "coordinates": [0, end], "position": [position[0], position[1] - length],
                              "direction": 90.0}
    if elements > 1:
        member["elements"] = elements
    return SpringModel({"valve_spring": member}, preload, rate)


def read_sheet(t: Table, units: UnitSystem, name: str, coordinate: int) -> SpringSpec:
    """A data sheet's keys (module doc) checked: a :class:`vtool.solvers.model.spring.SpringSpec`."""
    L, P = units.length, units.pressure
    d = t.number("wire_diameter", unit=L, min_exclusive=0.0, max_value=1e3)
    D = t.number("coil_diameter", unit=L, min_exclusive=0.0, max_value=1e4)
    if D <= 2.0 * d:
        raise InputError(t.field("coil_diameter"), D, f"> 2 wire_diameter ({2.0 * d:g}) (spring index D/d > 2)", L)
    n_t = t.number("total_coils", min_exclusive=0.0, max_value=1e3)
    n_a = t.number("active_coils", min_exclusive=0.0, max_value=1e3)
    if n_a > n_t:
        raise InputError(t.field("active_coils"), n_a, f"<= total_coils ({n_t:g})")
    free = t.number("free_length", unit=L, min_exclusive=0.0, max_value=1e4)
    installed = t.number("installed_length", unit=L, min_exclusive=0.0, max_value=1e4)
    if installed > free:
        raise InputError(t.field("installed_length"), installed, f"<= free_length ({free:g})", L)
    solid = t.number("solid_length", unit=L, required=False, min_exclusive=0.0, max_value=1e4)
    if solid is not None and solid >= installed:
        raise InputError(t.field("solid_length"), solid, f"< installed_length ({installed:g})", L)
    G = t.number("shear_modulus", unit=P, min_exclusive=0.0, max_value=1e16)
    rho = t.number("density", unit=units.density, min_exclusive=0.0, max_value=1e9)
    height = t.number("wire_height", unit=L, required=False, min_exclusive=0.0, max_value=1e3)
    if height is not None and not 0.5 * d <= height <= 2.0 * d:
        raise InputError(t.field("wire_height"), height, f"within 0.5 .. 2 wire_diameter ({0.5 * d:g} .. {2 * d:g})", L)
    rm, law = tensile_strength(t, units, d)
    fatigue = t.number("fatigue_limit", unit=P, required=False, min_exclusive=0.0, max_value=1e16)
    if fatigue is not None and fatigue > rm:
        raise InputError(t.field("fatigue_limit"), fatigue, f"<= tensile_strength ({rm:g})", P)
    ratio = t.number("shear_ratio", default=SHEAR_RATIO, min_exclusive=0.0, max_value=1.0)
    coils: tuple[float, ...] = ()
    pitches: tuple[float, ...] = ()
    if t.has("segment_coils") or t.has("segment_pitches"):
        coils = tuple(t.numbers("segment_coils"))
        pitches = tuple(t.numbers("segment_pitches", unit=L))
        if len(coils) != len(pitches) or not 1 <= len(coils) <= MAX_ELEMENTS:
            raise InputError(t.field("segment_pitches"), len(pitches),
                             f"as many entries as segment_coils ({len(coils)}), 1 to {MAX_ELEMENTS}")
        if any(c <= 0.0 for c in coils) or abs(sum(coils) - n_a) > 1e-9 * n_a:
            raise InputError(t.field("segment_coils"), list(coils), f"positive, summing to active_coils ({n_a:g})")
        axial = d if height is None else height
        if any(p <= axial for p in pitches):
            raise InputError(t.field("segment_pitches"), list(pitches), f"each > the wire's axial size ({axial:g})", L)
    lengths: tuple[float, ...] = ()
    forces: tuple[float, ...] = ()
    if t.has("lengths") or t.has("forces"):
        lengths = tuple(t.numbers("lengths", unit=L))
        forces = tuple(t.numbers("forces", unit=units.force))
        if len(lengths) != len(forces) or len(lengths) < 2:
            raise InputError(t.field("forces"), len(forces), f"as many entries as lengths ({len(lengths)}), >= 2")
        if np.any(np.diff(lengths) >= 0.0) or np.any(np.diff(forces) <= 0.0):
            raise InputError(t.field("lengths"), list(lengths), "lengths decreasing and forces increasing")
        if not lengths[-1] <= installed <= lengths[0]:
            raise InputError(t.field("installed_length"), installed,
                             f"within the table's lengths ({lengths[-1]:g} .. {lengths[0]:g})", L)
        if coils:
            raise InputError(t.field("lengths"), list(lengths), "a table or a pitch diagram, not both")
    return SpringSpec(name, d, D, n_a, n_t, free, installed, G, rho, rm, coordinate, fatigue, solid, ratio,
                      coils, pitches, lengths, forces, wire_height=height, strength_law=law)


def tensile_strength(t: Table, units: UnitSystem, d: float) -> tuple[float, tuple[float, float] | None]:
    """``tensile_strength``: a number (the preset's pressure unit), or R_m = A / d^m at the wire's diameter:
    a material of :data:`vtool.solvers.model.spring.STRENGTH_MATERIALS` ("VDSiCrV": A, m fitted to its table,
    within the table's diameters), or ``{A = ..., m = ...}`` (A in MPa mm^m, d in mm). Returns (R_m, (A, m))."""
    raw = t.raw("tensile_strength")
    if not isinstance(raw, str | dict):
        return t.number("tensile_strength", unit=units.pressure, min_exclusive=0.0, max_value=1e16), None
    d_mm = d * units.metres_per_length * 1e3
    if isinstance(raw, str):
        table = STRENGTH_MATERIALS[t.string("tensile_strength", choices=tuple(STRENGTH_MATERIALS))]
        low, high = table[0][0], table[-1][0]
        if not low - 0.3 <= d_mm <= high:
            raise InputError(t.field("wire_diameter"), d, f"within {low - 0.3:g} .. {high:g} mm for the "
                             f"tensile strength law of {raw} (its table's diameters)", units.length)
        A, m = fitted_strength_law(table)
    else:
        law = t.table("tensile_strength")
        A = law.number("A", unit="MPa*mm^m", min_exclusive=0.0, max_value=1e6)
        m = law.number("m", min_value=0.0, max_value=1.0)
        law.finish()
    return power_law_strength(A, m, d_mm) * 1e6 / units.pascals_per_pressure, (A, m)


def sheet_spring_model(t: Table, units: UnitSystem, end: int, first_new: int,
                       position: tuple[float, float]) -> SpringModel:
    """A data-sheet spring (and its ``inner`` nested spring): bars from the head to coordinate ``end``.

    Without a pitch diagram the spring is one bar of rate k and the active coils' mass, split into
    ``elements``; with one, a chain of one bar per segment (its coils' rate and mass) through new
    coordinates numbered from ``first_new``. A nested ``[train.spring.inner]`` is a second spring in
    parallel (same keys; its interference friction with the outer spring is left out).
    """
    inner_t = t.table("inner", required=False)
    springs = [(t, "valve_spring")] + ([(inner_t, "inner_spring")] if inner_t is not None else [])
    members: dict[str, dict[str, Any]] = {}
    coordinates: list[dict[str, Any]] = []
    clearances: list[dict[str, Any]] = []
    sheets: list[dict[str, Any]] = []
    preload = rate = 0.0
    for table, name in springs:
        spec = read_sheet(table, units, name, end)
        if spec.segment_coils and float(closing_forces(spec).min()) < spec.preload * (1.0 - 1e-12):
            raise InputError(table.field("installed_length"), spec.installed_length,
                             "a length at which no pitch segment is closed yet (the model's segments are linear "
                             "bars)", units.length)
        elements = table.integer("elements", default=1, min_value=1, max_value=MAX_ELEMENTS)
        contact = table.string("coil_contact", default="linear", choices=("linear", "none"))
        block = table.number("block_stiffness", unit=units.stiffness, required=False, min_exclusive=0.0,
                             max_value=1e13)
        ratio = table.number("block_damping_ratio", default=BLOCK_DAMPING_RATIO, min_value=0.0, max_value=10.0)
        table.finish()
        x = position[0] + (0.0 if name == "valve_spring" else 0.05 * spec.installed_length)
        base = (x, position[1] - spec.installed_length)
        if spec.segment_coils:
            rates = segment_rates(spec)
            nodes = [0]
            for i in range(len(rates) - 1):
                coordinates.append({"name": f"{name} coil node {i + 1}", "motion": "translation"})
                nodes.append(first_new + len(coordinates) - 1)
            nodes.append(end)
            if contact == "linear":
                made = coil_contacts(spec, nodes, block, ratio)
                clearances += made
                spec = replace(spec, contacts=tuple(c["name"] for c in made))
            spec = replace(spec, nodes=tuple(nodes[1:-1]))
            share = spec.installed_length / spec.active_coils
            below = 0.0
            for i, (n_i, k_i) in enumerate(zip(spec.segment_coils, rates, strict=True)):
                members[f"{name}_{i + 1}"] = {
                    "element": "bar", "length": n_i * share, "stiffness": float(k_i),
                    "mass": spec.wire_mass(n_i),
                    "coordinates": [nodes[i], nodes[i + 1]], "position": [base[0], base[1] + below],
                    "direction": 90.0}
                below += n_i * share
        else:
            member: dict[str, Any] = {"element": "bar", "length": spec.installed_length, "stiffness": spec.rate,
                                      "mass": spec.active_mass, "coordinates": [0, end], "position": list(base),
                                      "direction": 90.0}
            if elements > 1:
                member["elements"] = elements
            members[name] = member
        preload += spec.preload
        rate += spec.rate
        sheets.append(sheet_document(spec))
    t.finish()
    return SpringModel(members, preload, rate, coordinates, clearances, sheets)


def coil_contacts(spec: SpringSpec, nodes: list[int], block: float | None, ratio: float) -> list[dict[str, Any]]:
    """One compliant clearance per pitch segment: its coils touch when the segment's compression
    q_top - q_bottom reaches its free coil gap n_i (p_i - d) (the bars are unloaded at q = 0, and a train's
    spring end moves with the valve's lift, so compression is positive), i.e. the clearance
    ``ahead`` = top node, ``behind`` = bottom node (0: the ground under the first segment), ``sense`` = -1,
    ``opening`` = n_i (p_i - d). Closed, a spring of ``block`` (default BLOCK_FACTOR k_i) and a dashpot of
    ``ratio`` of critical act across the segment (module constants)."""
    rates = segment_rates(spec)
    gaps = np.asarray(spec.segment_coils) * (np.asarray(spec.segment_pitches) - spec.axial_wire)
    return [{"name": f"{spec.name} coils {i + 1}", "ahead": nodes[i + 1], "behind": nodes[i],
             "kind": "internal" if nodes[i] else "external", "state": "enabled", "restitution": 0.0,
             "contact": "linear", "contact_stiffness": float(block if block is not None else BLOCK_FACTOR * k_i),
             "contact_damping_ratio": ratio, "opening": float(gap), "sense": -1}
            for i, (k_i, gap) in enumerate(zip(rates, gaps, strict=True))]


def sheet_document(spec: SpringSpec) -> dict[str, Any]:
    """The explicit form's ``[[springs]]`` entry of a data sheet (read back by :func:`load_sheets`)."""
    doc: dict[str, Any] = {"name": spec.name, "coordinate": spec.coordinate}
    for key in ("wire_diameter", "coil_diameter", "active_coils", "total_coils", "free_length", "installed_length",
                "shear_modulus", "density", "tensile_strength", "fatigue_limit", "shear_ratio", "wire_height"):
        value = getattr(spec, key)
        if value is not None:
            doc[key] = value
    if spec.solid_length_given is not None:
        doc["solid_length"] = spec.solid_length_given
    if spec.segment_coils:
        doc["segment_coils"], doc["segment_pitches"] = list(spec.segment_coils), list(spec.segment_pitches)
        doc["nodes"] = list(spec.nodes)
        if spec.contacts:
            doc["contacts"] = list(spec.contacts)
    if spec.table_lengths:
        doc["lengths"], doc["forces"] = list(spec.table_lengths), list(spec.table_forces)
    return doc


def load_sheets(top: Table, units: UnitSystem, n: int) -> tuple[SpringSpec, ...]:
    """The explicit form's ``[[springs]]`` (data sheets for the spring checks; the members carry the model)."""
    if not top.has("springs"):
        return ()
    raw = top.raw("springs")
    if not isinstance(raw, list) or not all(isinstance(x, dict) for x in raw) or len(raw) > 8:
        raise InputError(top.field("springs"), raw, "an array of at most 8 tables (data sheets)")
    result = []
    for i, item in enumerate(raw):
        t = Table(item, f"springs[{i}]")
        name = t.string("name")
        coordinate = t.integer("coordinate", min_value=1, max_value=10_000)
        if coordinate > n:
            raise InputError(t.field("coordinate"), coordinate, f"an elastic coordinate (1 .. {n})")
        sheet = read_sheet(t, units, name, coordinate)
        if sheet.segment_coils:
            nodes = t.numbers("nodes")
            if len(nodes) != len(sheet.segment_coils) - 1 or any(k != int(k) or not 1 <= k <= n for k in nodes):
                raise InputError(t.field("nodes"), nodes, f"{len(sheet.segment_coils) - 1} coordinates in 1 .. {n}")
            sheet = replace(sheet, nodes=tuple(int(k) for k in nodes))
            if t.has("contacts"):
                names = [c.get("name") for c in top.raw("clearances") or [] if isinstance(c, dict)]
                contacts = t.raw("contacts")
                if (not isinstance(contacts, list) or len(contacts) != len(sheet.segment_coils)
                        or not all(isinstance(x, str) and x in names for x in contacts)):
                    raise InputError(t.field("contacts"), t.raw("contacts"),
                                     f"{len(sheet.segment_coils)} clearance names (one per pitch segment)")
                sheet = replace(sheet, contacts=tuple(contacts))
        result.append(sheet)
        t.finish()
    return tuple(result)


def describe(spec: SpringSpec, units: UnitSystem) -> str:
    """One line of what the loader derived from a data sheet (rate, mass, preload, solid length, surge)."""
    f = spec.surge_frequencies(1)[0]
    return (f"{spec.name}: rate {spec.rate:.5g} {units.stiffness}, active mass {spec.active_mass:.4g} {units.mass} "
            f"(whole wire {spec.total_mass:.4g}), installed preload {spec.preload:.5g} {units.force}, "
            f"solid length {spec.solid_length:.4g} {units.length}, first surge {f:.5g} Hz"
            + (f", tensile strength {spec.tensile_strength:.5g} {units.pressure} (R_m = {spec.strength_law[0]:.5g} / "
               f"d^{spec.strength_law[1]:.4g}, MPa and mm)" if spec.strength_law else ""))


def describe_document(explicit: dict[str, Any]) -> list[str]:
    """:func:`describe` of each data sheet of an expanded document (``vtool presets expand`` prints them)."""
    from vtool.units import UNIT_SYSTEMS

    units = UNIT_SYSTEMS[explicit["units"]]
    n = len(explicit["coordinates"])
    return [describe(s, units) for s in load_sheets(Table(explicit, ""), units, n)]
