"""Wall and floor assessments: from a spec to allowable boom pressures and design curves.

``assess(spec)`` is the one entry point for both preset kinds. Every result
carries the statement of the DAF source (pulse or envelope) it used.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from vtool.assessments.cancel import Cancel
from vtool.assessments.sonic_boom.criteria import Criterion, allowable_pressure
from vtool.assessments.sonic_boom.pulses import Pulse, make_pulse, read_pulse_csv
from vtool.assessments.sonic_boom.response import check_damping
from vtool.assessments.sonic_boom.spec import (
    DURATION_LIMITS,
    FREQUENCY_LIMITS,
    BoomFloorSpec,
    BoomLoading,
    BoomWallSpec,
    FloorSpec,
    UnitSystem,
    WallSpec,
)
from vtool.assessments.sonic_boom.spectra import EnvelopeSpec, daf_at
from vtool.assessments.sonic_boom.structures import (
    FloorOscillator,
    flexural_rigidity,
    floor_stiffness,
    plate_omega,
    pseudo_height,
)
from vtool.errors import InputError


@dataclass(frozen=True)
class Structure:
    """Derived properties of one wall or floor, in the preset's units."""

    name: str
    mass: float  # per unit area (wall) or total (floor)
    loaded_area: float  # 1 for a wall (per unit area), l * d for a floor
    frequencies: dict[str, float]  # source ("measured", "plate formula", "columns") -> Hz
    details: dict[str, float]  # pseudo-height, D, k, ... for the report


@dataclass(frozen=True)
class LimitRow:
    """One allowable pressure: structure, frequency source, tau, criterion."""

    structure: str
    frequency_source: str
    frequency: float  # Hz
    tau: float  # s
    ratio: float  # tau / T
    criterion: str
    response: str
    daf: float
    pressure: float  # preset pressure unit
    pressure_alt: float  # units.alt_pressure
    normalized: float  # limit / DAF: p+/(m omega) [length/s] (velocity), p+ S [length] (displacement)
    in_range: bool
    tentative: bool


@dataclass(frozen=True)
class DesignCurve:
    """Allowable pressure against frequency for one structure, criterion and tau."""

    structure: str
    criterion: str
    tau: float
    frequency: np.ndarray
    pressure: np.ndarray


@dataclass(frozen=True)
class Assessment:
    kind: str
    title: str
    units: UnitSystem
    source: str  # statement of the DAF source(s)
    structures: tuple[Structure, ...]
    rows: tuple[LimitRow, ...]
    curves: tuple[DesignCurve, ...]
    criteria: tuple[Criterion, ...]


def boom_source(boom: BoomLoading) -> Pulse | EnvelopeSpec:
    """The pulse or envelope a loading uses (reads the pulse CSV if there is one)."""
    check_damping(boom.damping)
    if boom.pulse is not None:
        return make_pulse(boom.pulse)
    if boom.pulse_csv is not None:
        return read_pulse_csv(boom.pulse_csv)
    if boom.envelope is not None:
        return boom.envelope
    raise InputError("boom", "no pulse", "one of: type, csv, envelope")


def wall_structure(wall: WallSpec, units: UnitSystem) -> Structure:
    m = wall.surface_weight / units.gravity
    D = flexural_rigidity(wall.youngs_modulus, wall.thickness, wall.poisson_ratio)
    if wall.height is not None:
        b = wall.height
    elif wall.net_area is not None:
        b = pseudo_height(wall.net_area, wall.base_width)
        if wall.pseudo_height_rule == "whole-unit":
            if b < 0.5:
                raise InputError(f"walls.{wall.name}.pseudo_height_rule", wall.pseudo_height_rule,
                                 f"exact (net_area/base_width = {b:.3g} {units.length} rounds to 0)")
            b = float(round(b))
    else:
        b = None
    freqs: dict[str, float] = {}
    details = {"mass_per_area": m, "flexural_rigidity": D}
    if b is not None:
        details["pseudo_height"] = b
        freqs["plate formula"] = plate_omega(wall.base_width, b, D, m) / (2.0 * math.pi)
    if wall.measured_frequency is not None:
        freqs["measured"] = wall.measured_frequency
    if not freqs:
        raise InputError(f"walls.{wall.name}", "no frequency",
                         "net_area or height (plate formula), or measured_frequency")
    return check_frequencies(Structure(wall.name, m, 1.0, freqs, details),
                             "thickness, youngs_modulus, poisson_ratio, surface_weight, sizes")


def floor_structure(floor: FloorSpec, units: UnitSystem) -> Structure:
    k = floor_stiffness(floor.columns, floor.youngs_modulus, floor.moment_of_inertia,
                        floor.storey_height)
    M = floor.floor_weight / units.gravity
    osc = FloorOscillator(M, k, floor.storey_height * floor.face_width)
    freqs = {"columns": osc.frequency}
    if floor.measured_frequency is not None:
        freqs["measured"] = floor.measured_frequency
    details = {"stiffness": k, "mass": M, "loaded_area": osc.loaded_area}
    return check_frequencies(Structure(floor.name, M, osc.loaded_area, freqs, details),
                             "columns, youngs_modulus, moment_of_inertia, storey_height, "
                             "floor_weight")


def check_frequencies(structure: Structure, inputs: str) -> Structure:
    """Refuse a structure frequency outside :data:`FREQUENCY_LIMITS` before any DAF work."""
    low, high = FREQUENCY_LIMITS
    for source, f in structure.frequencies.items():
        if not (math.isfinite(f) and low <= f <= high):
            raise InputError(f"{structure.name} {source} frequency", f"{f:.4g}",
                             f"in [{low:g}, {high:g}] (check {inputs})", "Hz")
    return structure


def _static_per_pressure(structure: Structure, frequency: np.ndarray | float) -> np.ndarray:
    """``S``: static deflection per unit pressure, ``A / (M omega^2)``.

    A wall is taken per unit area (``A = 1``, ``M`` = mass per unit area); a
    floor has ``A = l d`` and its mass ``M``, so that with the column-model
    frequency ``M omega^2 = k`` and ``S = l d / k`` (equations 11-13); with a
    measured frequency the stiffness is ``M omega^2``. Design curves hold
    the mass and vary the frequency.
    """
    omega = 2.0 * math.pi * np.asarray(frequency, dtype=float)
    return structure.loaded_area / (structure.mass * omega**2)


def _daf_table(source: Pulse | EnvelopeSpec, ratios: dict[str, list[np.ndarray]],
               damping: float, cancel: Cancel | None = None
               ) -> tuple[dict[str, tuple[np.ndarray, np.ndarray]], str]:
    """One DAF evaluation per quantity over every ``tau/T`` any result needs."""
    table: dict[str, tuple[np.ndarray, np.ndarray]] = {}
    statements = []
    for quantity, parts in ratios.items():
        grid = np.unique(np.concatenate(parts))
        daf, statement = daf_at(source, grid, quantity, damping, cancel)
        table[quantity] = (grid, daf)
        statements.append(statement)
    return table, " | ".join(statements)


def _lookup(table: dict[str, tuple[np.ndarray, np.ndarray]], quantity: str,
            ratio: np.ndarray) -> np.ndarray:
    grid, daf = table[quantity]
    return daf[np.searchsorted(grid, ratio)]


def assess(spec: BoomWallSpec | BoomFloorSpec, cancel: Cancel | None = None) -> Assessment:
    """Allowable peak overpressures for every structure, frequency, tau and criterion.

    ``cancel`` is polled between DAF evaluations (:mod:`vtool.assessments.cancel`).
    """
    source = boom_source(spec.boom)
    units = spec.units
    if isinstance(spec, BoomWallSpec):
        structures = tuple(wall_structure(w, units) for w in spec.walls)
    else:
        structures = tuple(floor_structure(f, units) for f in spec.floors)
    taus = spec.boom.positive_durations
    if isinstance(source, Pulse) and source.tau_seconds is not None:
        taus = (source.tau_seconds,)  # a tabulated pulse fixes its own duration
        low, high = DURATION_LIMITS
        if not low <= source.tau_seconds <= high:
            raise InputError(f"{source.label} positive duration", f"{source.tau_seconds:.4g}",
                             f"in [{low:g}, {high:g}] (time column in seconds?)", "s")
    design = spec.design
    freqs = np.linspace(design.f_min, design.f_max, design.points)
    needed: dict[str, list[np.ndarray]] = {}
    for crit in spec.criteria:
        parts = needed.setdefault(crit.response, [])
        for tau in taus:
            parts.append(tau * freqs)
            for st in structures:
                parts.append(tau * np.array(list(st.frequencies.values())))
    table, statement = _daf_table(source, needed, spec.boom.damping, cancel)

    rows: list[LimitRow] = []
    for st in structures:
        for fsource, f in st.frequencies.items():
            for tau in taus:
                ratio = np.array([tau * f])
                for crit in spec.criteria:
                    daf = _lookup(table, crit.response, ratio)
                    S = _static_per_pressure(st, f)
                    p = float(allowable_pressure(crit, daf, f, S, units.metres_per_length)[0])
                    scale = float(S) * (2.0 * math.pi * f if crit.response == "velocity" else 1.0)
                    rows.append(LimitRow(st.name, fsource, f, tau, float(ratio[0]), crit.name,
                                         crit.response, float(daf[0]), p,
                                         p * units.alt_per_pressure, p * scale, crit.in_range(f),
                                         crit.tentative))
    curves: list[DesignCurve] = []
    for st in structures:
        for tau in taus:
            for crit in spec.criteria:
                daf = _lookup(table, crit.response, tau * freqs)
                S = _static_per_pressure(st, freqs)
                pressures = allowable_pressure(crit, daf, freqs, S, units.metres_per_length)
                curves.append(DesignCurve(st.name, crit.name, tau, freqs, pressures))
    return Assessment(spec.kind, spec.title, units, statement, structures, tuple(rows),
                      tuple(curves), spec.criteria)
