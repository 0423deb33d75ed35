"""Limits an engineer signs off, as data: a preset's ``[checks]`` table, evaluated against a run.

A preset gives limits by name (``contact_pressure_max = 1500.0`` in its
pressure unit); :func:`evaluate` turns each into a :class:`Check`: the value
from the run (or from the geometry), the limit, the unit, pass or fail and
the margin (limit - value for a ``max`` check, value - limit for a ``min``
one, in the unit; negative when failed).

Extending: each name is one :class:`CheckKind` in :data:`CHECKS` with its
sense, its unit kind and an ``evaluate(spec, trace)`` function returning the
value (``None`` when the run or preset has nothing to judge, e.g. no oil).
The preset loader accepts exactly the names in :data:`CHECKS` (so a later
module adds spring or lash-adjuster checks by calling :func:`register`
before presets load: import it from :mod:`vtool.solvers.studies.checks`'s
callers, e.g. the spring module, and the names appear in the loader's
error message and docs).

``trace`` is any object with ``spec``, ``cam_angle`` (deg), ``force(name)``
and ``events`` (:class:`vtool.solvers.trace.Trace`); geometry-only checks
accept ``trace=None``.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import asdict, dataclass
from functools import lru_cache
from typing import Any

import numpy as np

from vtool.solvers.model.spec import MechanismSpec

MAX, MIN = "max", "min"


@dataclass(frozen=True)
class Check:
    """One evaluated limit."""

    name: str
    description: str
    value: float | None
    limit: float
    unit: str
    sense: str  # "max": value <= limit passes; "min": value >= limit passes
    passed: bool | None  # None: nothing to judge (value None)
    margin: float | None  # in the unit; negative when failed

    @property
    def margin_percent(self) -> float | None:
        if self.margin is None or self.limit == 0.0:
            return None
        return 100.0 * self.margin / abs(self.limit)

    def as_dict(self) -> dict[str, Any]:
        return asdict(self) | {"margin_percent": self.margin_percent}

    def text(self) -> str:
        sign = "<=" if self.sense == MAX else ">="
        if self.value is None:
            return f"  n/a   {self.description}: nothing to judge (limit {sign} {self.limit:.6g} {self.unit})"
        word = "PASS" if self.passed else "FAIL"
        percent = "" if self.margin_percent is None else f", {self.margin_percent:.1f} %"
        return (f"  {word}  {self.description}: {self.value:.6g} {self.unit} (limit {sign} {self.limit:.6g} "
                f"{self.unit}; margin {self.margin:.4g} {self.unit}{percent})")


@dataclass(frozen=True)
class CheckKind:
    """A check a preset may name: its sense, unit kind and how to get its value."""

    name: str
    sense: str
    unit_kind: str  # "pressure", "length", "velocity", "force", "deg", "ratio" (no unit)
    description: str
    evaluate: Callable[[MechanismSpec, Any], float | None]
    needs_run: bool = True


CHECKS: dict[str, CheckKind] = {}


def register(kind: CheckKind) -> None:
    """Add a check name (idempotent for the same name)."""
    CHECKS[kind.name] = kind


def unit_of(spec: MechanismSpec, unit_kind: str) -> str:
    units = spec.unit_system
    return {"pressure": units.pressure, "length": units.length, "velocity": units.velocity,
            "force": units.force, "deg": "deg", "ratio": ""}[unit_kind]


def evaluate(spec: MechanismSpec, trace: Any = None) -> list[Check]:
    """Every limit of ``spec.checks`` judged (run checks need ``trace``; without it they are n/a)."""
    result = []
    for limit in spec.checks:
        kind = CHECKS[limit.name]
        value = None if (kind.needs_run and trace is None) else kind.evaluate(spec, trace)
        if value is None or not math.isfinite(value):
            passed, margin, value = None, None, None
        else:
            margin = limit.limit - value if kind.sense == MAX else value - limit.limit
            passed = margin >= 0.0
        result.append(Check(limit.name, kind.description, value, limit.limit, unit_of(spec, kind.unit_kind),
                            kind.sense, passed, margin))
    return result


# ----- the cam-contact and seat checks (issue 39) --------------------------------------------------

def _stress(spec: MechanismSpec, trace: Any) -> dict:
    from vtool.solvers.model.camstress import stress_summary

    cam = next(c.name for c in spec.clearances if c.behind == spec.cam.coordinate)
    return stress_summary(spec, trace.cam_angle, trace.force(cam))


def _geometry(spec: MechanismSpec) -> Any:
    return _cached_profile(spec.follower, spec.lift_law)


@lru_cache(maxsize=16)
def _cached_profile(follower: Any, law: Any) -> Any:
    from vtool.solvers.model.camshape import cam_profile

    return cam_profile(follower, law)


def _contact_pressure(spec: MechanismSpec, trace: Any) -> float | None:
    return None if spec.follower is None else _stress(spec, trace).get("max_contact_pressure")


def _film(spec: MechanismSpec, trace: Any) -> float | None:
    if spec.follower is None or spec.follower.oil is None:
        return None
    return _stress(spec, trace).get("min_film_thickness")


def _radius(spec: MechanismSpec, trace: Any) -> float | None:
    if spec.follower is None:
        return None
    rho = _geometry(spec).curvature_radius
    convex = rho[rho > 0.0]
    return float(rho.min()) if (rho <= 0.0).any() and spec.follower.kind == "flat" else (
        float(convex.min()) if convex.size else None)


def _pressure_angle(spec: MechanismSpec, trace: Any) -> float | None:
    if spec.follower is None:
        return None
    from vtool.solvers.model.camstress import revolution

    return float(np.abs(revolution(spec.follower, spec.lift_law).pressure_angle_deg).max())


def _travel(spec: MechanismSpec, trace: Any) -> float | None:
    if spec.follower is None or spec.follower.kind != "flat":
        return None
    from vtool.solvers.model.camstress import revolution

    return float(np.nanmax(np.abs(revolution(spec.follower, spec.lift_law).contact_travel)))


def _seating(spec: MechanismSpec, trace: Any) -> float | None:
    seats = {c.name for c in spec.clearances if c.kind == "external" and c.behind != spec.cam.coordinate}
    speeds = [abs(e.relative_velocity) for e in trace.events if e.clearance in seats and e.kind == "closed"]
    return max(speeds) if speeds else None


for _kind in (
    CheckKind("contact_pressure_max", MAX, "pressure", "cam contact pressure (Hertz p0, largest at the output rows)",
              _contact_pressure),
    CheckKind("film_thickness_min", MIN, "length", "oil film (Dowson-Higginson h_min, smallest while loaded)", _film),
    CheckKind("cam_radius_min", MIN, "length", "cam radius of curvature (smallest convex; negative: undercut)",
              _radius, needs_run=False),
    CheckKind("pressure_angle_max", MAX, "deg", "pressure angle (largest)", _pressure_angle, needs_run=False),
    CheckKind("contact_travel_max", MAX, "length", "contact travel on the flat face (largest |offset|)",
              _travel, needs_run=False),
    CheckKind("seating_velocity_max", MAX, "velocity", "valve seating velocity (largest)", _seating),
):
    register(_kind)


# ----- the valve spring's checks (issue 40; data-sheet springs, vtool.solvers.model.spring) -----------

def _springs(spec: MechanismSpec, trace: Any) -> list[dict]:
    from vtool.solvers.model.spring import run_report

    return run_report(spec.springs, trace) if spec.springs else []


def _spring_stress(spec: MechanismSpec, trace: Any) -> float | None:
    report = _springs(spec, trace)
    return max(r["max_stress"] for r in report) if report else None


def _spring_fatigue(spec: MechanismSpec, trace: Any) -> float | None:
    factors = [r["fatigue_factor"] for r in _springs(spec, trace) if r["fatigue_factor"] is not None]
    return min(factors) if factors else None


def _coil_bind(spec: MechanismSpec, trace: Any) -> float | None:
    report = _springs(spec, trace)
    return min(r["coil_bind_margin"] for r in report) if report else None


for _kind in (
    CheckKind("spring_stress_max", MAX, "pressure", "valve spring shear stress (Bergstraesser, largest)",
              _spring_stress),
    CheckKind("spring_fatigue_min", MIN, "ratio", "valve spring fatigue safety factor (Goodman, last cycle)",
              _spring_fatigue),
    CheckKind("coil_bind_margin_min", MIN, "length", "valve spring coil-bind margin (shortest - solid length, or "
              "a pitch segment's coil gap)",
              _coil_bind),
):
    register(_kind)


def checks_text(checks: list[dict]) -> list[str]:
    """Summary lines of evaluated checks (as :meth:`Check.as_dict` gives them)."""
    lines = ["", "checks ([checks] limits):"]
    for c in checks:
        fields = {k: v for k, v in c.items() if k != "margin_percent"}
        lines.append(Check(**fields).text())
    return lines
