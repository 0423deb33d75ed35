"""Frozen specs of a sonic-boom study (what a ``boom_wall`` / ``boom_floor`` preset holds).

Validation happens in :mod:`vtool.presets.boom`; these classes only carry
the values, with their units named by :class:`vtool.units.UnitSystem`.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from vtool.assessments.sonic_boom.criteria import Criterion
from vtool.assessments.sonic_boom.pulses import PulseParams
from vtool.assessments.sonic_boom.spectra import EnvelopeSpec
from vtool.units import BOOM_UNIT_SYSTEMS, UnitSystem

__all__ = ["DURATION_LIMITS", "FREQUENCY_LIMITS", "PSEUDO_HEIGHT_RULES", "UNIT_SYSTEMS", "BoomFloorSpec",
           "BoomLoading", "BoomWallSpec", "DesignRange", "FloorSpec", "UnitSystem", "WallSpec"]

#: Structure frequencies (Hz) accepted: measured, from the plate formula or the
#: column model, and the design-curve range.
FREQUENCY_LIMITS: tuple[float, float] = (1e-2, 1e3)
#: Boom positive durations (s) accepted: booms last 0.05-0.5 s.
DURATION_LIMITS: tuple[float, float] = (1e-4, 10.0)


#: the boom's unit systems (thesis 001's g = 386.4 in/s^2): :data:`vtool.units.BOOM_UNIT_SYSTEMS`
UNIT_SYSTEMS: dict[str, UnitSystem] = BOOM_UNIT_SYSTEMS


@dataclass(frozen=True)
class BoomLoading:
    """The boom: positive durations ``tau`` (s), and the pulse or envelope used.

    Exactly one of ``pulse`` (an idealized type), ``pulse_csv`` (a tabulated
    history) and ``envelope`` is set.
    """

    positive_durations: tuple[float, ...] = (0.1,)
    pulse: PulseParams | None = None
    pulse_csv: str | None = None
    envelope: EnvelopeSpec | None = field(default_factory=EnvelopeSpec)
    damping: float = 0.0


@dataclass(frozen=True)
class WallSpec:
    """One wall. The plate height is ``height`` or ``net_area / base_width``.

    ``pseudo_height_rule`` (:data:`PSEUDO_HEIGHT_RULES`) says whether that
    quotient is used as is or rounded to a whole length unit.
    """

    name: str
    base_width: float
    thickness: float
    youngs_modulus: float
    poisson_ratio: float
    surface_weight: float
    net_area: float | None = None
    height: float | None = None
    measured_frequency: float | None = None  # Hz
    pseudo_height_rule: str = "exact"  # or "whole-unit": round net_area/base_width as the thesis


#: How the pseudo-height ``b = net area / a`` is taken: ``exact``, or rounded to
#: a whole length unit (``whole-unit``) as the thesis prints "31565/207 = 152 in".
PSEUDO_HEIGHT_RULES: tuple[str, ...] = ("exact", "whole-unit")


@dataclass(frozen=True)
class FloorSpec:
    """Top floor of a multi-storey building on ``columns`` fixed-fixed columns."""

    name: str
    columns: int
    youngs_modulus: float
    moment_of_inertia: float
    storey_height: float
    face_width: float
    floor_weight: float
    measured_frequency: float | None = None  # Hz


@dataclass(frozen=True)
class DesignRange:
    """Frequencies (Hz) for the design curves."""

    f_min: float = 1.0
    f_max: float = 50.0
    points: int = 200


@dataclass(frozen=True)
class BoomWallSpec:
    title: str
    units: UnitSystem
    boom: BoomLoading
    walls: tuple[WallSpec, ...]
    criteria: tuple[Criterion, ...]
    design: DesignRange = DesignRange()
    kind: str = "boom_wall"


@dataclass(frozen=True)
class BoomFloorSpec:
    title: str
    units: UnitSystem
    boom: BoomLoading
    floors: tuple[FloorSpec, ...]
    criteria: tuple[Criterion, ...]
    design: DesignRange = DesignRange()
    kind: str = "boom_floor"
