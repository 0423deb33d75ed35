"""Unit systems: the one place their names and constants live.

A preset states its unit system once (``units = "in-lbf-s"``); every number in
it is then in that system, and every output (CSV header, JSON ``*_unit`` key,
TUI field, summary) names the unit. :class:`UnitSystem` carries the base
names (length, force, time, mass), the standard gravity that turns a weight
into a mass, and the derived names as properties.

The two theses round g differently, so each domain has its own table:

* :data:`UNIT_SYSTEMS` (valve train, plate): the valve-train thesis' g =
  386.0 in/s² (Gnilka 1971, subroutine MCK: ``GRAV/386.0D0/``);
* :data:`BOOM_UNIT_SYSTEMS` (sonic boom): thesis 001's g = 386.4 in/s², with
  pressure quoted also in a second unit (lb/ft², kPa).

The valve-train solver reads it through :mod:`vtool.solvers.units` (same
objects). The boom and plate presets still define their own classes
(``assessments/sonic_boom/spec.py``, ``presets/plate.py``); they can move here
by building :class:`UnitSystem` with ``pressure_name``, ``metres_per_length``
and the ``alt_pressure`` fields.
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
    pressure_name: str = ""  # e.g. "psi"; default force/length^2
    metres_per_length: float = 1.0
    alt_pressure: str = ""  # a second pressure unit engineers quote (boom: lb/ft^2, kPa)
    alt_per_pressure: float = 1.0

    @property
    def stiffness(self) -> str:
        return f"{self.force}/{self.length}"

    @property
    def pressure(self) -> str:
        return self.pressure_name or f"{self.force}/{self.length}^2"

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
    "in-lbf-s": UnitSystem("in-lbf-s", "in", "lbf", "s", "lbf*s^2/in", 386.0, metres_per_length=0.0254),
    "SI": UnitSystem("SI", "m", "N", "s", "kg", 9.80665),
}

BOOM_UNIT_SYSTEMS: dict[str, UnitSystem] = {
    # thesis 001's system; g = 386.4 in/s^2 as in its arithmetic (section 1.5.2)
    "in-lbf-s": UnitSystem("in-lbf-s", "in", "lbf", "s", "lbf s^2/in", 386.4, "psi", 0.0254, "lb/ft^2", 144.0),
    "m-N-s": UnitSystem("m-N-s", "m", "N", "s", "N s^2/m", 9.80665, "Pa", 1.0, "kPa", 1e-3),
}
