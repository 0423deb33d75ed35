"""Sonic-boom presets: TOML document <-> ``BoomWallSpec`` / ``BoomFloorSpec``.

``load(doc)`` validates every field once, at this boundary, and raises
:class:`vtool.errors.InputError` naming the field, value, allowed range and
unit; ``dump(spec)`` writes the same structure back (a loaded-then-dumped
preset loads to an equal spec). See ``presets/boom-brick-wall.toml``.

Layout::

    kind = "boom_wall"            # or "boom_floor"
    title = "..."
    units = "in-lbf-s"            # or "m-N-s"
    criteria = ["damage-threshold", "safe-limit"]   # built-in or [[criterion]] names

    [boom]
    positive_durations = [0.1]    # s
    pulse = "envelope"            # or N, P, Q, R, T (with s, r1, r2, alpha, beta), or "csv"
    damping = 0.0
    [boom.envelope]               # optional; defaults are the thesis' ranges
    types = ["N", "P", "Q", "R", "T"]
    s = [1.6, 2.2, 0.1]           # first, last, step
    r1 = [0.0, 0.5, 0.1]

    [[walls]]  /  [[floors]]      # one table per structure
    [[criterion]]                 # optional user criteria
    [design]                      # optional: f_min, f_max (Hz), points
"""

from __future__ import annotations

from typing import Any

from vtool.assessments.sonic_boom.criteria import BUILTIN, UNITS, Criterion
from vtool.assessments.sonic_boom.pulses import PULSE_TYPES, PulseParams, validate
from vtool.assessments.sonic_boom.spec import (
    UNIT_SYSTEMS,
    BoomFloorSpec,
    BoomLoading,
    BoomWallSpec,
    DesignRange,
    FloorSpec,
    UnitSystem,
    WallSpec,
)
from vtool.assessments.sonic_boom.spectra import EnvelopeSpec, _steps
from vtool.errors import InputError
from vtool.presets.fields import Table

KINDS = ("boom_wall", "boom_floor")
PULSES = ("envelope", "csv", *PULSE_TYPES)
DEFAULT_CRITERIA = {
    "boom_wall": ("damage-threshold", "safe-limit"),
    "boom_floor": ("reiher-meister-perceptible", "reiher-meister-annoying",
                   "reiher-meister-unpleasant"),
}


def load(doc: dict[str, Any]) -> BoomWallSpec | BoomFloorSpec:
    """Validate a parsed boom preset and return its frozen spec."""
    top = Table(doc, "")
    kind = top.string("kind", choices=KINDS)
    title = top.string("title", default="")
    top.string("notes", default="")
    units = UNIT_SYSTEMS[top.string("units", choices=tuple(UNIT_SYSTEMS))]
    custom = {c.name: c for c in (_criterion(t) for t in top.array_of_tables("criterion", required=False))}
    names = top.raw("criteria", list(DEFAULT_CRITERIA[kind]))
    if not isinstance(names, list) or not names or not all(isinstance(n, str) for n in names):
        raise InputError("criteria", names, "a non-empty list of criterion names")
    known = {**BUILTIN, **custom}
    criteria = []
    for name in names:
        if name not in known:
            raise InputError("criteria", name, f"one of: {', '.join(known)}")
        criteria.append(known[name])
    boom = _boom(top.table("boom"))  # type: ignore[arg-type]
    design_table = top.table("design", required=False)
    design = _design(design_table) if design_table is not None else DesignRange()
    if kind == "boom_wall":
        walls = tuple(_wall(t, units) for t in top.array_of_tables("walls"))
        if not walls:
            raise InputError("walls", "none", "at least one [[walls]] table")
        _unique([w.name for w in walls], "walls")
        top.finish()
        return BoomWallSpec(title, units, boom, walls, tuple(criteria), design)
    floors = tuple(_floor(t, units) for t in top.array_of_tables("floors"))
    if not floors:
        raise InputError("floors", "none", "at least one [[floors]] table")
    _unique([f.name for f in floors], "floors")
    top.finish()
    return BoomFloorSpec(title, units, boom, floors, tuple(criteria), design)


def _unique(names: list[str], field: str) -> None:
    seen: set[str] = set()
    for name in names:
        if name in seen:
            raise InputError(f"{field}.name", name, "a name not used by another entry")
        seen.add(name)


def _criterion(t: Table) -> Criterion:
    name = t.string("name")
    if name in BUILTIN:
        raise InputError(t.field("name"), name, "a name that is not built in")
    crit = Criterion(
        name=name,
        source=t.string("source"),
        response=t.string("response", choices=("velocity", "displacement")),
        value=t.number("value", min_exclusive=0.0),
        unit=t.string("unit", choices=tuple(UNITS)),
        tentative=t.boolean("tentative", default=False),
        f_min=t.number("f_min", unit="Hz", min_value=0.0, required=False),
        f_max=t.number("f_max", unit="Hz", min_value=0.0, required=False),
    )
    t.finish()
    return crit.check(t.path)


def _range3(t: Table, key: str, default: tuple[float, ...]) -> tuple[float, ...]:
    if not t.has(key):
        t.raw(key)
        return default
    values = t.numbers(key)
    if len(values) != 3 or values[2] <= 0.0 or values[1] < values[0]:
        raise InputError(t.field(key), values, "[first, last, step] with last >= first, step > 0")
    return _steps(*values)


def _boom(t: Table) -> BoomLoading:
    taus = t.numbers("positive_durations", unit="s", default=[0.1])
    if not taus or any(not (v > 0.0) for v in taus):
        raise InputError(t.field("positive_durations"), taus, "a non-empty list of values > 0", "s")
    pulse = t.string("pulse", default="envelope", choices=PULSES)
    damping = t.number("damping", default=0.0, min_value=0.0, max_exclusive=1.0)
    params = None
    csv = None
    env = None
    if pulse in PULSE_TYPES:
        s = t.number("s", default=2.0, min_value=1.0)
        r1 = t.number("r1", default=0.0, min_value=0.0, max_exclusive=1.0)
        r2 = t.number("r2", required=False, min_value=0.0)
        alpha = t.number("alpha", required=False, min_value=0.0)
        beta = t.number("beta", required=False)
        params = validate(PulseParams(pulse, s, r1, r2, alpha, beta), prefix=f"{t.path}.")
        params = PulseParams(pulse, s, r1, r2, alpha, beta)
    elif pulse == "csv":
        csv = t.string("csv")
    else:
        et = t.table("envelope", required=False)
        if et is None:
            env = EnvelopeSpec()
        else:
            types = et.raw("types", list(PULSE_TYPES))
            if not isinstance(types, list) or not types or any(k not in PULSE_TYPES for k in types):
                raise InputError(et.field("types"), types, f"a non-empty list from: {', '.join(PULSE_TYPES)}")
            default = EnvelopeSpec()
            env = EnvelopeSpec(
                tuple(types),
                _range3(et, "s", default.s_values),
                _range3(et, "r1", default.r1_values),
                et.number("alpha", required=False, min_value=0.0),
                et.number("beta", required=False),
            )
            et.finish()
            env.members()  # validates every member
    t.finish()
    return BoomLoading(tuple(taus), params, csv, env, damping)


def _design(t: Table) -> DesignRange:
    f_min = t.number("f_min", unit="Hz", default=1.0, min_exclusive=0.0)
    f_max = t.number("f_max", unit="Hz", default=50.0, min_exclusive=f_min)
    points = t.integer("points", default=200, min_value=2, max_value=100_000)
    t.finish()
    return DesignRange(f_min, f_max, points)


def _wall(t: Table, u: UnitSystem) -> WallSpec:
    wall = WallSpec(
        name=t.string("name"),
        base_width=t.number("base_width", unit=u.length, min_exclusive=0.0),
        thickness=t.number("thickness", unit=u.length, min_exclusive=0.0),
        youngs_modulus=t.number("youngs_modulus", unit=u.pressure, min_exclusive=0.0),
        poisson_ratio=t.number("poisson_ratio", min_exclusive=-1.0, max_exclusive=0.5),
        surface_weight=t.number("surface_weight", unit=u.surface_weight, min_exclusive=0.0),
        net_area=t.number("net_area", unit=f"{u.length}^2", min_exclusive=0.0, required=False),
        height=t.number("height", unit=u.length, min_exclusive=0.0, required=False),
        measured_frequency=t.number("measured_frequency", unit="Hz", min_exclusive=0.0,
                                    required=False),
    )
    if wall.net_area is not None and wall.height is not None:
        raise InputError(t.field("height"), wall.height, "absent when net_area is given (pseudo-height rule)",
                         u.length)
    if wall.net_area is None and wall.height is None and wall.measured_frequency is None:
        raise InputError(t.field("measured_frequency"), None,
                         "a value, or net_area / height for the plate formula", "Hz")
    t.finish()
    return wall


def _floor(t: Table, u: UnitSystem) -> FloorSpec:
    floor = FloorSpec(
        name=t.string("name"),
        columns=t.integer("columns", min_value=1),
        youngs_modulus=t.number("youngs_modulus", unit=u.pressure, min_exclusive=0.0),
        moment_of_inertia=t.number("moment_of_inertia", unit=f"{u.length}^4", min_exclusive=0.0),
        storey_height=t.number("storey_height", unit=u.length, min_exclusive=0.0),
        face_width=t.number("face_width", unit=u.length, min_exclusive=0.0),
        floor_weight=t.number("floor_weight", unit=u.force, min_exclusive=0.0),
        measured_frequency=t.number("measured_frequency", unit="Hz", min_exclusive=0.0,
                                    required=False),
    )
    t.finish()
    return floor


def _drop_none(d: dict[str, Any]) -> dict[str, Any]:
    return {k: v for k, v in d.items() if v is not None}


def dump(spec: BoomWallSpec | BoomFloorSpec) -> dict[str, Any]:
    """The preset document for a spec (``load(dump(spec)) == spec``)."""
    doc: dict[str, Any] = {"kind": spec.kind, "title": spec.title, "units": spec.units.name}
    doc["criteria"] = [c.name for c in spec.criteria]
    custom = [c for c in spec.criteria if c.name not in BUILTIN]
    boom = spec.boom
    b: dict[str, Any] = {"positive_durations": list(boom.positive_durations),
                         "damping": boom.damping}
    if boom.pulse is not None:
        p = boom.pulse
        b.update(_drop_none({"pulse": p.kind, "s": p.s, "r1": p.r1, "r2": p.r2,
                             "alpha": p.alpha, "beta": p.beta}))
    elif boom.pulse_csv is not None:
        b.update({"pulse": "csv", "csv": boom.pulse_csv})
    else:
        env = boom.envelope or EnvelopeSpec()
        b["pulse"] = "envelope"
        e: dict[str, Any] = {"types": list(env.types)}
        for key, values in (("s", env.s_values), ("r1", env.r1_values)):
            step = values[1] - values[0] if len(values) > 1 else 1.0
            e[key] = [values[0], values[-1], round(step, 12)]
        e.update(_drop_none({"alpha": env.alpha, "beta": env.beta}))
        b["envelope"] = e
    doc["boom"] = b
    doc["design"] = {"f_min": spec.design.f_min, "f_max": spec.design.f_max,
                     "points": spec.design.points}
    if isinstance(spec, BoomWallSpec):
        doc["walls"] = [_drop_none(dict(vars(w))) for w in spec.walls]
    else:
        doc["floors"] = [_drop_none(dict(vars(f))) for f in spec.floors]
    if custom:
        doc["criterion"] = [_drop_none(dict(vars(c))) for c in custom]
    return doc
