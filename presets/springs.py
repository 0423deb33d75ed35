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

from dataclasses import dataclass, field
from typing import Any

from vtool.errors import InputError
from vtool.presets.fields import Table
from vtool.units import UnitSystem

MAX_ELEMENTS = 64
SPRING_KEYS = ("rate", "preload", "mass", "length", "free_length", "installed_length", "elements")


@dataclass(frozen=True)
class SpringModel:
    """What a spring adds to the explicit model (see the module doc)."""

    members: dict[str, dict[str, Any]]
    preload: float
    rate: float
    coordinates: list[dict[str, Any]] = field(default_factory=list)
    clearances: list[dict[str, Any]] = field(default_factory=list)


def spring_model(t: Table, units: UnitSystem, end: int, first_new: int,
                 position: tuple[float, float] = (0.0, 0.0)) -> SpringModel:
    """The valve spring of ``[train.spring]`` acting between the ground and coordinate ``end``.

    ``first_new`` is the number the spring's own coordinates would take (none today);
    ``position`` places the spring's fixed end in drawings.
    """
    del first_new  # a single bar adds no coordinate
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
