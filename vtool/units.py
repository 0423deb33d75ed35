"""Unit systems: the one place their names and constants live.

A preset states its unit system once (``units = "in-lbf-s"``); every number in
it is then in that system, and every output (CSV header, JSON ``*_unit`` key,
TUI field, summary) names the unit. :class:`UnitSystem` carries the base
names (length, force, time, mass), the standard gravity that turns a weight
into a mass, and the derived names as properties.

The domains name their units differently (thesis 001 says psi where the
valve train says lbf/in^2) and the two theses round g differently, so each
domain has its own table of the one class:

* :data:`UNIT_SYSTEMS` (valve train): the valve-train thesis' g = 386.0
  in/s² (Gnilka 1971, subroutine MCK: ``GRAV/386.0D0/``), SI, and ``mm-N-s``
  (today's engine data: mm, N, s, MPa, mass in N s²/mm = t, cam degrees);
* :data:`BOOM_UNIT_SYSTEMS` (sonic boom): thesis 001's g = 386.4 in/s², pressure
  in psi / Pa and also in a second unit engineers quote booms in (lb/ft², kPa);
* :data:`PLATE_UNIT_SYSTEMS` (plate): the valve train's system names, density
  named per length^4 (``lbf*s^2/in^4``) and SI pressure in Pa.

The valve-train solver reads it through :mod:`vtool.solvers.model.units`, the boom
through :mod:`vtool.assessments.sonic_boom.spec`, the plate through
:mod:`vtool.assessments.plate.spec` (same objects). The SI factors
(``metres_per_length``, ``pascals_per_pressure``, ``newtons_per_force``) let a
loader state physical bounds once, in SI.
"""

from __future__ import annotations

import math
from dataclasses import dataclass


@dataclass(frozen=True)
class UnitSystem:
    """Names of the units of one consistent system, its gravity and its SI factors."""

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
    pascals_per_pressure: float = 1.0
    newtons_per_force: float = 1.0
    density_name: str = ""  # e.g. "kg/m^3"; default mass/length^3

    @property
    def stiffness(self) -> str:
        return f"{self.force}/{self.length}"

    @property
    def pressure(self) -> str:
        return self.pressure_name or f"{self.force}/{self.length}^2"

    @property
    def surface_weight(self) -> str:
        """Weight per area (a wall's surface weight), always force/length^2."""
        return f"{self.force}/{self.length}^2"

    @property
    def specific_weight(self) -> str:
        return f"{self.force}/{self.length}^3"

    @property
    def density(self) -> str:
        return self.density_name or f"{self.mass}/{self.length}^3"

    @property
    def kg_per_m3(self) -> float:
        """SI density per density unit, mass being force*time^2/length: N/m / m^3."""
        return self.newtons_per_force / self.metres_per_length**4

    @property
    def velocity(self) -> str:
        return f"{self.length}/{self.time}"

    @property
    def acceleration(self) -> str:
        return f"{self.length}/{self.time}^2"

    @property
    def damping(self) -> str:
        return f"{self.force}*{self.time}/{self.length}"


INCH = 0.0254  # m
PSI = 6894.757293168361  # Pa
LBF = 4.4482216152605  # N

UNIT_SYSTEMS: dict[str, UnitSystem] = {
    # Thesis system: mass in lbf*s^2/in ("slinch"), g = 386.0 in/s^2 as in MCK.
    "in-lbf-s": UnitSystem("in-lbf-s", "in", "lbf", "s", "lbf*s^2/in", 386.0, metres_per_length=INCH,
                           pascals_per_pressure=PSI, newtons_per_force=LBF),
    "SI": UnitSystem("SI", "m", "N", "s", "kg", 9.80665),
    # engine practice: millimetres, newtons, seconds; mass then is N*s^2/mm (= 1 tonne), density
    # t/mm^3 (steel 7.85e-9), pressure N/mm^2 = MPa; angles stay cam degrees (a lift table in crank
    # degrees is converted by the train loader, presets/trains.py)
    "mm-N-s": UnitSystem("mm-N-s", "mm", "N", "s", "N*s^2/mm", 9806.65, "MPa", metres_per_length=1e-3,
                         pascals_per_pressure=1e6, newtons_per_force=1.0, density_name="t/mm^3"),
}

BOOM_UNIT_SYSTEMS: dict[str, UnitSystem] = {
    # thesis 001's system; g = 386.4 in/s^2 as in its arithmetic (section 1.5.2)
    "in-lbf-s": UnitSystem("in-lbf-s", "in", "lbf", "s", "lbf s^2/in", 386.4, "psi", INCH, "lb/ft^2", 144.0,
                           pascals_per_pressure=PSI, newtons_per_force=LBF),
    "m-N-s": UnitSystem("m-N-s", "m", "N", "s", "N s^2/m", 9.80665, "Pa", 1.0, "kPa", 1e-3),
}

PLATE_UNIT_SYSTEMS: dict[str, UnitSystem] = {
    # the valve train's system names; the plate studies use no gravity
    "in-lbf-s": UnitSystem("in-lbf-s", "in", "lbf", "s", "lbf*s^2/in", 386.0, "lbf/in^2", INCH,
                           pascals_per_pressure=PSI, newtons_per_force=LBF, density_name="lbf*s^2/in^4"),
    "SI": UnitSystem("SI", "m", "N", "s", "kg", 9.80665, "Pa", density_name="kg/m^3"),
}


def cam_speed(rpm: float) -> float:
    """The cam's angular speed ω in rad/s at ``rpm`` rev/min (ω = 2π rpm / 60): the one place a speed
    becomes ω (:attr:`vtool.solvers.model.spec.RunSpec.omega` and every study read it)."""
    return rpm * math.pi / 30.0
