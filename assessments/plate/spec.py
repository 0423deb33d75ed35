"""The frozen spec of a plate preset (what ``presets/plate-*.toml`` holds), beside its physics.

Validation happens in :mod:`vtool.presets.plate`; these classes carry the
values and name their units.
"""

from __future__ import annotations

from dataclasses import dataclass

from vtool.assessments.plate.study import Study


@dataclass(frozen=True)
class PlateUnits:
    """Unit names of one consistent system, as a plate preset uses them, and their SI factors."""

    length: str
    pressure: str
    density: str
    force: str
    metres: float = 1.0  # per length unit
    pascals: float = 1.0  # per pressure unit
    kg_per_m3: float = 1.0  # per density unit


#: Same system names as the valve-train presets.
UNIT_SYSTEMS: dict[str, PlateUnits] = {
    "in-lbf-s": PlateUnits("in", "lbf/in^2", "lbf*s^2/in^4", "lbf", 0.0254, 6894.757293168361,
                           4.4482216152605 / 0.0254**4),
    "SI": PlateUnits("m", "Pa", "kg/m^3", "N"),
}


@dataclass(frozen=True)
class PlateSpec:
    """A validated plate preset: a study with its title and units."""

    title: str
    units: str
    study: Study
    element: str  # default element of the cases
    nx: int  # default mesh of the cases
    ny: int
    notes: str = ""
    kind: str = "plate"

    @property
    def unit_system(self) -> PlateUnits:
        return UNIT_SYSTEMS[self.units]
