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

from pathlib import Path
from typing import Any

from vtool.assessments.sonic_boom.criteria import BUILTIN, UNITS, Criterion
from vtool.assessments.sonic_boom.pulses import PULSE_TYPES, PulseParams, validate
from vtool.assessments.sonic_boom.spec import (
    DURATION_LIMITS,
    FREQUENCY_LIMITS,
    PSEUDO_HEIGHT_RULES,
    UNIT_SYSTEMS,
    BoomFloorSpec,
    BoomLoading,
    BoomWallSpec,
    DesignRange,
    FloorSpec,
    UnitSystem,
    WallSpec,
)
from vtool.assessments.sonic_boom.spectra import FAMILIES, EnvelopeSpec, _steps
from vtool.errors import InputError
from vtool.presets.fields import Table

KINDS = ("boom_wall", "boom_floor")
PULSES = ("envelope", "csv", *PULSE_TYPES)
DEFAULT_CRITERIA = {
    "boom_wall": ("damage-threshold", "safe-limit"),
    "boom_floor": ("reiher-meister-perceptible", "reiher-meister-annoying",
                   "reiher-meister-unpleasant"),
}


#: Physical bounds, in SI, checked before any numerics (docs/sonic-boom.md, "Limits").
LIMITS_SI: dict[str, tuple[float, float]] = {
    "length": (1e-3, 1e4),  # m: thickness, widths, heights
    "area": (1e-6, 1e8),  # m^2
    "inertia": (1e-12, 1e2),  # m^4
    "modulus": (1e3, 1e13),  # Pa
    "surface_weight": (1e-3, 1e6),  # N/m^2
    "weight": (1e-3, 1e10),  # N
}
POISSON_LIMITS = (-0.9, 0.499)
MAX_LIST = 100  # durations, structures, criteria
MAX_COLUMNS = 100_000
MAX_POINTS = 10_000
MAX_PULSE_PARAMETER = 100.0  # s, r2, alpha, |beta|


def _limits(u: UnitSystem, quantity: str) -> tuple[float, float]:
    """``LIMITS_SI[quantity]`` in the preset's units."""
    low, high = LIMITS_SI[quantity]
    scale = {
        "length": 1.0 / u.metres_per_length,
        "area": 1.0 / u.metres_per_length**2,
        "inertia": 1.0 / u.metres_per_length**4,
        "modulus": 1.0 / u.pascals_per_pressure,
        "surface_weight": u.metres_per_length**2 / u.newtons_per_force,
        "weight": 1.0 / u.newtons_per_force,
    }[quantity]
    return float(f"{low * scale:.3g}"), float(f"{high * scale:.3g}")


def _bounded(t: Table, key: str, u: UnitSystem, quantity: str, unit: str,
             required: bool = True) -> float:
    low, high = _limits(u, quantity)
    return t.number(key, unit=unit, min_value=low, max_value=high, required=required)


def _short_list(t: Table, key: str, limit: int = MAX_LIST) -> None:
    """Refuse an over-long list before it is read (and echoed) element by element."""
    value = t.data.get(key) if isinstance(t.data, dict) else None
    if isinstance(value, list) and len(value) > limit:
        raise InputError(t.field(key), f"a list of {len(value)} values", f"at most {limit} values")


def load(doc: dict[str, Any], base: str | Path | None = None) -> BoomWallSpec | BoomFloorSpec:
    """Validate a parsed boom preset and return its frozen spec.

    ``base`` is the preset's folder: a relative pulse CSV path resolves
    against it (not against the working directory). An echoed bad value is
    cut to a readable length.
    """
    try:
        return _load(doc, base)
    except InputError as exc:
        raise short_error(exc) from None


def short_error(exc: InputError, limit: int = 80) -> InputError:
    """``exc`` with its echoed value (and field) cut to ``limit`` characters."""
    text = repr(exc.value)
    if len(text) <= limit and len(exc.field) <= limit:
        return exc
    value = exc.value if len(text) <= limit else text[: limit - 3] + "..."
    return InputError(exc.field[:limit], value, exc.expected[: 4 * limit], exc.unit)


def _load(doc: dict[str, Any], base: str | Path | None) -> BoomWallSpec | BoomFloorSpec:
    top = Table(doc, "")
    kind = top.string("kind", choices=KINDS)
    title = top.string("title", default="")
    top.string("notes", default="", multiline=True)
    units = UNIT_SYSTEMS[top.string("units", choices=tuple(UNIT_SYSTEMS))]
    for key in ("criterion", "criteria", "walls", "floors"):
        _short_list(top, key)
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
    boom = _boom(top.table("boom"), base)
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
        value=t.number("value", min_exclusive=0.0, max_value=1e9),
        unit=t.string("unit", choices=tuple(UNITS)),
        tentative=t.boolean("tentative", default=False),
        f_min=t.number("f_min", unit="Hz", min_value=0.0, max_value=1e6, required=False),
        f_max=t.number("f_max", unit="Hz", min_value=0.0, max_value=1e6, required=False),
    )
    t.finish()
    return crit.check(t.path)


def _range3(t: Table, key: str, default: tuple[float, ...]) -> tuple[float, ...]:
    if not t.has(key):
        t.raw(key)
        return default
    _short_list(t, key, 3)
    values = t.numbers(key)
    if len(values) != 3 or not values[2] > 0.0 or values[1] < values[0]:
        raise InputError(t.field(key), values, "[first, last, step] with last >= first, step > 0")
    return _steps(values[0], values[1], values[2], field=t.field(key))


def _boom(t: Table, base: str | Path | None) -> BoomLoading:
    _short_list(t, "positive_durations")
    taus = t.numbers("positive_durations", unit="s", default=[0.1])
    low, high = DURATION_LIMITS
    bad = [v for v in taus if not (low <= v <= high)]
    if not taus or bad:
        raise InputError(t.field("positive_durations"), bad[0] if bad else taus,
                         f"a non-empty list of values in [{low:g}, {high:g}]", "s")
    pulse = t.string("pulse", default="envelope", choices=PULSES)
    damping = t.number("damping", default=0.0, min_value=0.0, max_exclusive=1.0)
    params = None
    csv = None
    env = None
    top = MAX_PULSE_PARAMETER
    if pulse in PULSE_TYPES:
        s = t.number("s", default=2.0, min_value=1.0, max_value=top)
        r1 = t.number("r1", default=0.0, min_value=0.0, max_exclusive=1.0)
        r2 = t.number("r2", required=False, min_value=0.0, max_value=top)
        alpha = t.number("alpha", required=False, min_value=0.0, max_value=top)
        beta = t.number("beta", required=False, min_value=-top, max_value=top)
        params = validate(PulseParams(pulse, s, r1, r2, alpha, beta), prefix=f"{t.path}.")
        params = PulseParams(pulse, s, r1, r2, alpha, beta)
    elif pulse == "csv":
        csv = t.string("csv")
        if base is not None and csv and not Path(csv).is_absolute():
            csv = str(Path(base) / csv)
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
                et.number("alpha", required=False, min_value=0.0, max_value=top),
                et.number("beta", required=False, min_value=-top, max_value=top),
                et.string("family", default="thesis", choices=tuple(FAMILIES)),
            )
            et.finish()
            env.members()  # validates every member
    t.finish()
    return BoomLoading(tuple(taus), params, csv, env, damping)


def _design(t: Table) -> DesignRange:
    low, high = FREQUENCY_LIMITS
    f_min = t.number("f_min", unit="Hz", default=1.0, min_value=low, max_value=high)
    f_max = t.number("f_max", unit="Hz", default=50.0, min_exclusive=f_min, max_value=high)
    points = t.integer("points", default=200, min_value=2, max_value=MAX_POINTS)
    t.finish()
    return DesignRange(f_min, f_max, points)


def _wall(t: Table, u: UnitSystem) -> WallSpec:
    f_low, f_high = FREQUENCY_LIMITS
    wall = WallSpec(
        name=t.string("name"),
        base_width=_bounded(t, "base_width", u, "length", u.length),
        thickness=_bounded(t, "thickness", u, "length", u.length),
        youngs_modulus=_bounded(t, "youngs_modulus", u, "modulus", u.pressure),
        poisson_ratio=t.number("poisson_ratio", min_value=POISSON_LIMITS[0],
                               max_value=POISSON_LIMITS[1]),
        surface_weight=_bounded(t, "surface_weight", u, "surface_weight", u.surface_weight),
        net_area=_bounded(t, "net_area", u, "area", f"{u.length}^2", required=False),
        height=_bounded(t, "height", u, "length", u.length, required=False),
        measured_frequency=t.number("measured_frequency", unit="Hz", min_value=f_low,
                                    max_value=f_high, required=False),
        pseudo_height_rule=t.string("pseudo_height_rule", default="exact",
                                    choices=PSEUDO_HEIGHT_RULES),
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
        columns=t.integer("columns", min_value=1, max_value=MAX_COLUMNS),
        youngs_modulus=_bounded(t, "youngs_modulus", u, "modulus", u.pressure),
        moment_of_inertia=_bounded(t, "moment_of_inertia", u, "inertia", f"{u.length}^4"),
        storey_height=_bounded(t, "storey_height", u, "length", u.length),
        face_width=_bounded(t, "face_width", u, "length", u.length),
        floor_weight=_bounded(t, "floor_weight", u, "weight", u.force),
        measured_frequency=t.number("measured_frequency", unit="Hz", min_value=FREQUENCY_LIMITS[0],
                                    max_value=FREQUENCY_LIMITS[1], required=False),
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
        if env.family != "thesis":
            e["family"] = env.family
        b["envelope"] = e
    doc["boom"] = b
    doc["design"] = {"f_min": spec.design.f_min, "f_max": spec.design.f_max,
                     "points": spec.design.points}
    if isinstance(spec, BoomWallSpec):
        doc["walls"] = [{k: v for k, v in _drop_none(dict(vars(w))).items()
                         if k != "pseudo_height_rule" or v != "exact"} for w in spec.walls]
    else:
        doc["floors"] = [_drop_none(dict(vars(f))) for f in spec.floors]
    if custom:
        doc["criterion"] = [_drop_none(dict(vars(c))) for c in custom]
    return doc
