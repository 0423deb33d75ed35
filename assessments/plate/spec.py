"""The frozen spec of a plate preset (what ``presets/plate-*.toml`` holds), beside its physics.

Validation happens in :mod:`vtool.presets.plate`; these classes carry the
values and name their units.
"""

from __future__ import annotations

from dataclasses import dataclass

from vtool.assessments.plate.study import Study
from vtool.units import PLATE_UNIT_SYSTEMS, UnitSystem

#: the plate's unit systems (same names as the valve-train presets): one class, :mod:`vtool.units`
UNIT_SYSTEMS: dict[str, UnitSystem] = PLATE_UNIT_SYSTEMS


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
    def unit_system(self) -> UnitSystem:
        return UNIT_SYSTEMS[self.units]
