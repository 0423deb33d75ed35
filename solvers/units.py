"""Unit systems a preset can declare.

A preset states its unit system once (``units = "in-lbf-s"``); every number in
it is then in that system, and every output (CSV header, TUI field, summary)
names the unit. The thesis presets use the thesis' inch-pound-second system
with its g = 386.0 in/s² (Gnilka 1971, subroutine MCK: ``GRAV/386.0D0/``).
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class UnitSystem:
    """Names of the units of one consistent system, and its gravity."""

    name: str
    length: str
    force: str
    time: str
    mass: str
    gravity: float  # standard gravity in length/time², turns specific weight into density

    @property
    def stiffness(self) -> str:
        return f"{self.force}/{self.length}"

    @property
    def pressure(self) -> str:
        return f"{self.force}/{self.length}^2"

    @property
    def specific_weight(self) -> str:
        return f"{self.force}/{self.length}^3"

    @property
    def density(self) -> str:
        return f"{self.mass}/{self.length}^3"

    @property
    def velocity(self) -> str:
        return f"{self.length}/{self.time}"

    @property
    def acceleration(self) -> str:
        return f"{self.length}/{self.time}^2"

    @property
    def damping(self) -> str:
        return f"{self.force}*{self.time}/{self.length}"


UNIT_SYSTEMS: dict[str, UnitSystem] = {
    # Thesis system: mass in lbf*s^2/in ("slinch"), g = 386.0 in/s^2 as in MCK.
    "in-lbf-s": UnitSystem("in-lbf-s", "in", "lbf", "s", "lbf*s^2/in", 386.0),
    "SI": UnitSystem("SI", "m", "N", "s", "kg", 9.80665),
}
