"""Plate presets: TOML document <-> :class:`PlateSpec` (a condensed-plate study).

``load(doc)`` validates every field once and raises
:class:`vtool.errors.InputError` naming the field, the value, what is
allowed and the unit; master sets are checked against the mesh they apply
to (a constrained or non-existent DOF is an error here, not in the
solver). ``dump(spec)`` writes the same structure back, so a loaded preset
round-trips. See ``presets/plate-table2.toml`` for a commented example.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from vtool.assessments.plate.assembly import Mesh, Plate
from vtool.assessments.plate.constraints import free_dofs
from vtool.assessments.plate.elements import ELEMENTS
from vtool.assessments.plate.masters import NAMED_SETS, MasterSetError, labelled_set, named_set
from vtool.assessments.plate.model import METHODS, Case, MasterSelection
from vtool.assessments.plate.spec import UNIT_SYSTEMS, PlateSpec
from vtool.assessments.plate.study import (
    DEFAULT_PERIODS,
    MAX_EXACT_MODES,
    Study,
    TransientSettings,
    check_exact_cost,
    check_mesh_size,
)
from vtool.assessments.plate.transient import LOADS, MIN_OMEGA_MAX_H, RK4_LIMIT_THESIS
from vtool.errors import InputError
from vtool.presets.boom import short_error
from vtool.presets.fields import Table
from vtool.units import UnitSystem

__all__ = ["UNIT_SYSTEMS", "PlateSpec", "dump", "load"]  # specs live in assessments.plate.spec

MAX_MESH = 64
#: Physical bounds in SI, checked before any numerics (docs/plate.md, "Limits").
PLATE_LIMITS_SI: dict[str, tuple[float, float]] = {
    "a": (1e-3, 1e3),  # m
    "b": (1e-3, 1e3),  # m
    "thickness": (1e-6, 10.0),  # m
    "youngs_modulus": (1e3, 1e13),  # Pa
    "density": (1.0, 1e5),  # kg/m^3
}
POISSON_LIMITS = (-0.9, 0.499)
MAX_ASPECT = 100.0  # a/b and b/a
MAX_CASES = 50


def _si_scale(units: UnitSystem, key: str) -> float:
    """SI value per preset unit of ``key``."""
    return {"a": units.metres_per_length, "b": units.metres_per_length,
            "thickness": units.metres_per_length, "youngs_modulus": units.pascals_per_pressure,
            "density": units.kg_per_m3}[key]


def _mesh(t: Table, key: str, default: tuple[int, int] | None) -> tuple[int, int]:
    if default is not None and not t.has(key):
        t.raw(key)
        return default
    value = t.raw(key)
    ok = (
        isinstance(value, list) and len(value) == 2
        and all(isinstance(v, int) and not isinstance(v, bool) and 1 <= v <= MAX_MESH for v in value)
    )
    if not ok:
        raise InputError(t.field(key), value, f"[NX, NY], two integers in 1..{MAX_MESH} (elements along a and b)")
    return int(value[0]), int(value[1])


def _plate(t: Table, units: UnitSystem) -> Plate:
    unit = {"a": units.length, "b": units.length, "thickness": units.length,
            "youngs_modulus": units.pressure, "density": units.density}
    values = {}
    for key, (low, high) in PLATE_LIMITS_SI.items():
        scale = _si_scale(units, key)
        values[key] = t.number(key, unit=unit[key], min_value=float(f"{low / scale:.3g}"),
                               max_value=float(f"{high / scale:.3g}"))
    poisson = t.number("poisson", min_value=POISSON_LIMITS[0], max_value=POISSON_LIMITS[1])
    a, b = values["a"], values["b"]
    if not 1.0 / MAX_ASPECT <= a / b <= MAX_ASPECT:
        raise InputError(t.field("b"), b, f"within a factor {MAX_ASPECT:g} of a = {a:g}", units.length)
    if values["thickness"] > 0.5 * min(a, b):
        raise InputError(t.field("thickness"), values["thickness"],
                         f"<= half the shorter side, {0.5 * min(a, b):g} (a plate)", units.length)
    t.finish()
    return Plate(a=a, b=b, thickness=values["thickness"], youngs_modulus=values["youngs_modulus"],
                 poisson=poisson, density=values["density"])


def _masters(t: Table, mesh: Mesh, field: str) -> MasterSelection:
    has_masters, has_auto = t.has("masters"), t.has("auto")
    if has_masters == has_auto:
        t.raw("masters")
        t.raw("auto")
        raise InputError(field, None if not has_masters else "masters and auto",
                         "exactly one of: masters (a named set or a list of \"w@i,j\" labels), auto (a count)")
    free = free_dofs(mesh)
    where = f"free DOFs of the {mesh.nx}x{mesh.ny} {mesh.element.name} mesh"
    if has_auto:
        count = t.integer("auto", min_value=1, max_value=int(free.size))
        return MasterSelection(auto=count)
    value = t.raw("masters")
    try:
        if isinstance(value, str):
            if value not in NAMED_SETS:
                raise InputError(t.field("masters"), value,
                                 f"a named set ({', '.join(NAMED_SETS)}) or a list of \"w@i,j\" labels")
            named_set(mesh, value, free)
            return MasterSelection(named=value)
        if isinstance(value, list) and value and all(isinstance(v, str) for v in value):
            labelled_set(mesh, value, free)
            return MasterSelection(labels=tuple(value))
    except MasterSetError as exc:
        raise InputError(t.field("masters"), value, f"{where} ({exc})") from None
    raise InputError(t.field("masters"), value, "a named set or a non-empty list of \"w@i,j\" labels")


def _cases(top: Table, plate: Plate, element: str, mesh: tuple[int, int]) -> tuple[Case, ...]:
    raw = top.data.get("cases") if isinstance(top.data, dict) else None
    if isinstance(raw, list) and len(raw) > MAX_CASES:
        raise InputError("cases", f"{len(raw)} entries", f"at most {MAX_CASES}")
    tables = top.array_of_tables("cases")
    if not tables:
        raise InputError("cases", [], "at least one [[cases]] entry")
    cases, names = [], set()
    for t in tables:
        name = t.string("name")
        if not name or name in names:
            raise InputError(t.field("name"), name, "a unique, non-empty case name")
        names.add(name)
        case_element = t.string("element", default=element, choices=tuple(ELEMENTS))
        nx, ny = _mesh(t, "mesh", mesh)
        check_mesh_size(case_element, nx, ny, t.field("mesh"))
        grid = Mesh(plate, ELEMENTS[case_element], nx, ny)
        masters = _masters(t, grid, t.path)
        method = t.string("method", default="guyan", choices=METHODS)
        note = t.string("note", default="", multiline=True)
        t.finish()
        cases.append(Case(name, case_element, nx, ny, masters, method, note))
    return tuple(cases)


def _transient(t: Table | None, cases: tuple[Case, ...], plate: Plate) -> TransientSettings:
    if t is None:
        return TransientSettings()
    names = [c.name for c in cases]
    chosen = t.raw("cases", [])
    if not isinstance(chosen, list) or any(c not in names for c in chosen):
        raise InputError(t.field("cases"), chosen, f"a list of case names ({', '.join(names)})")
    loads = t.raw("loads", list(LOADS))
    if not isinstance(loads, list) or not loads or any(v not in LOADS for v in loads):
        raise InputError(t.field("loads"), loads, f"a non-empty list of: {', '.join(LOADS)}")
    raw = t.data.get("omega_max_h") if isinstance(t.data, dict) else None
    if isinstance(raw, list) and len(raw) > 10:
        raise InputError(t.field("omega_max_h"), f"a list of {len(raw)} values", "at most 10 values")
    steps = t.numbers("omega_max_h", default=[2.0, 1.0, 0.5])
    for v in steps:
        if not MIN_OMEGA_MAX_H <= v <= RK4_LIMIT_THESIS:
            raise InputError(t.field("omega_max_h"), v,
                             f">= {MIN_OMEGA_MAX_H:g} and <= {RK4_LIMIT_THESIS} (RK4 stability limit, eq. 44)")
    if not steps:
        raise InputError(t.field("omega_max_h"), steps, "at least one value")
    settings = TransientSettings(
        cases=tuple(chosen),
        loads=tuple(loads),
        omega_max_h=tuple(steps),
        periods=t.number("periods", default=DEFAULT_PERIODS, min_value=0.5, max_value=20.0),
        exact_modes=t.integer("exact_modes", default=200, min_value=2, max_value=MAX_EXACT_MODES),
        tolerance_pct=t.number("tolerance", unit="%", default=2.0, min_value=0.0, max_value=100.0),
        truncation_check=t.boolean("truncation_check", default=True),
    )
    t.finish()
    check_exact_cost(plate, settings, t.path)
    return settings


def load(doc: dict[str, Any], folder: Path | None = None) -> PlateSpec:
    """Validate a parsed plate preset and return its frozen spec (echoed values cut short).

    ``folder`` (the preset's folder) is accepted like every loader's; a plate preset names no file.
    """
    try:
        return _load(doc)
    except InputError as exc:
        raise short_error(exc) from None


def _load(doc: dict[str, Any]) -> PlateSpec:
    top = Table(doc, "")
    top.string("kind", choices=("plate",))
    title = top.string("title", default="")
    notes = top.string("notes", default="", multiline=True)
    units_name = top.string("units", choices=tuple(UNIT_SYSTEMS))
    units = UNIT_SYSTEMS[units_name]
    plate = _plate(top.table("plate"), units)
    s = top.table("study")
    assert s is not None
    element = s.string("element", choices=tuple(ELEMENTS))
    mesh = _mesh(s, "mesh", None)
    frequencies = s.integer("frequencies", default=6, min_value=1, max_value=100)
    conv = s.raw("convergence_meshes", [2, 4, 8])
    if not isinstance(conv, list) or len(conv) > 8 or any(
        isinstance(v, bool) or not isinstance(v, int) or not 1 <= v <= 32 for v in conv
    ) or len(set(conv)) != len(conv):
        shown = conv if not isinstance(conv, list) or len(conv) <= 8 else f"a list of {len(conv)} values"
        raise InputError(s.field("convergence_meshes"), shown,
                         "a list of at most 8 distinct integers in 1..32 (n x n meshes)")
    s.finish()
    check_mesh_size(element, mesh[0], mesh[1], s.field("mesh"))
    cases = _cases(top, plate, element, mesh)
    for case_element in dict.fromkeys(c.element for c in cases):
        for n in conv:
            check_mesh_size(case_element, n, n, "study.convergence_meshes")
    transient = _transient(top.table("transient", required=False), cases, plate)
    top.finish()
    study = Study(plate, cases, frequencies, tuple(conv), transient)
    return PlateSpec(title, units_name, study, element, mesh[0], mesh[1], notes)


def dump(spec: PlateSpec) -> dict[str, Any]:
    """The preset document of a spec (``load(dump(spec)) == spec``)."""
    p = spec.study.plate
    doc: dict[str, Any] = {"kind": "plate", "title": spec.title, "units": spec.units}
    if spec.notes:
        doc["notes"] = spec.notes
    doc["plate"] = {"a": p.a, "b": p.b, "thickness": p.thickness, "youngs_modulus": p.youngs_modulus,
                    "poisson": p.poisson, "density": p.density}
    doc["study"] = {"element": spec.element, "mesh": [spec.nx, spec.ny],
                    "frequencies": spec.study.frequencies,
                    "convergence_meshes": list(spec.study.convergence_meshes)}
    cases = []
    for c in spec.study.cases:
        entry: dict[str, Any] = {"name": c.name}
        if c.element != spec.element:
            entry["element"] = c.element
        if (c.nx, c.ny) != (spec.nx, spec.ny):
            entry["mesh"] = [c.nx, c.ny]
        if c.masters.named is not None:
            entry["masters"] = c.masters.named
        elif c.masters.labels:
            entry["masters"] = list(c.masters.labels)
        else:
            entry["auto"] = c.masters.auto
        if c.method != "guyan":
            entry["method"] = c.method
        if c.note:
            entry["note"] = c.note
        cases.append(entry)
    doc["cases"] = cases
    t = spec.study.transient
    doc["transient"] = {"cases": list(t.cases), "loads": list(t.loads), "omega_max_h": list(t.omega_max_h),
                        "periods": t.periods, "exact_modes": t.exact_modes, "tolerance": t.tolerance_pct}
    return doc
