"""``[hla]``: a hydraulic lash adjuster in a bar member's place (:mod:`vtool.solvers.model.hla`).

The explicit table (a ``[train.hla]`` expands to it, :mod:`vtool.presets.trains`)
names the bar ``member`` it sits in (a stiffness-given bar: the closed
chamber's linear stiffness stays there, the element adds the rest) and
``sense`` (what the member's positive elongation is for the adjuster:
``"compression"``, it shortens, or ``"extension"``). The data, in the preset's
unit system (mm-N-s: mm, mm^3, N/mm, N, MPa; the oil's viscosity in mPa*s as
``[train.oil]``):

* ``plunger_diameter``, ``chamber_volume`` (at zero extension);
* ``spring_rate``, ``spring_preload`` (the plunger spring, pushing it out);
* ``gap`` (radial clearance of the plunger in its bore), ``gap_length``,
  ``viscosity``: the leakage Q = π d h³ Δp / (12 μ L);
* ``supply_pressure`` (the gallery's, gauge), ``check_conductance``
  (volume per time and pressure above ``crack_pressure``);
* ``bulk_pressures`` / ``bulk_moduli`` (the oil's bulk modulus against gauge
  pressure; default 1,600 MPa at every pressure), ``air_fraction``
  (entrained air by volume at atmospheric pressure, default 0);
* ``damping`` (viscous, the plunger in its bore; default 0),
  ``initial_pressure`` (default: the pressure that carries the static start's
  load, or the supply pressure where that is lower).
"""

from __future__ import annotations

from typing import Any

from vtool.errors import InputError
from vtool.presets.fields import Table
from vtool.solvers.model.hla import SENSES, HLAPlace, HLASpec
from vtool.units import UnitSystem

OIL_BULK_MODULUS = 1.6e9  # Pa, a mineral oil's (the default at every pressure)
MPA_S = 1e-3  # Pa*s per mPa*s
#: the data keys (model units) in reading order
DATA = ("plunger_diameter", "chamber_volume", "spring_rate", "spring_preload", "gap", "gap_length", "viscosity",
        "supply_pressure", "check_conductance", "crack_pressure", "bulk_pressures", "bulk_moduli", "air_fraction",
        "damping", "initial_pressure")


def read_data(t: Table, units: UnitSystem) -> tuple[HLASpec, float | None, dict[str, Any]]:
    """The adjuster's data from a table (``[hla]`` or ``[train.hla]``): its SI spec, its initial pressure (Pa or
    None) and the keys as given (model units, for a saved copy)."""
    L, P, F = units.metres_per_length, units.pascals_per_pressure, units.newtons_per_force
    length, pressure = units.length, units.pressure
    conductance = f"{length}^3/({units.time}*{pressure})"
    given: dict[str, Any] = {}

    def number(key: str, unit: str, default: float | None = None, **bounds: Any) -> float:
        value = t.number(key, unit=unit, default=default, **bounds)
        if t.has(key):
            given[key] = t.raw(key)
        return value

    d = number("plunger_diameter", length, min_exclusive=0.0, max_value=1e3)
    volume = number("chamber_volume", f"{length}^3", min_exclusive=0.0, max_value=1e9)
    rate = number("spring_rate", units.stiffness, default=0.0, min_value=0.0, max_value=1e9)
    preload = number("spring_preload", units.force, default=0.0, min_value=0.0, max_value=1e9)
    gap = number("gap", length, min_value=0.0, max_value=1.0 * 1e-3 / L)  # up to 1 mm
    gap_length = number("gap_length", length, min_exclusive=0.0, max_value=1e3)
    viscosity = number("viscosity", "mPa*s", min_exclusive=0.0, max_value=1e5)
    supply = number("supply_pressure", pressure, min_value=0.0, max_value=1e8 / P)  # up to 1,000 bar
    check = number("check_conductance", conductance, min_value=0.0, max_value=1e-6 * P / L**3)
    crack = number("crack_pressure", pressure, default=0.0, min_value=0.0, max_value=1e8 / P)
    pressures = t.numbers("bulk_pressures", unit=pressure, default=[0.0])
    moduli = t.numbers("bulk_moduli", unit=pressure, default=[OIL_BULK_MODULUS / P])
    for key in ("bulk_pressures", "bulk_moduli"):
        if t.has(key):
            given[key] = t.raw(key)
    if len(pressures) != len(moduli) or not pressures:
        raise InputError(t.field("bulk_moduli"), moduli, f"as many values as bulk_pressures ({len(pressures)})",
                         pressure)
    if any(b <= a for a, b in zip(pressures, pressures[1:], strict=False)):
        raise InputError(t.field("bulk_pressures"), pressures, "increasing", pressure)
    if any(not 1e6 / P <= k <= 1e11 / P for k in moduli):
        raise InputError(t.field("bulk_moduli"), moduli, f"each >= {1e6 / P:g} and <= {1e11 / P:g}", pressure)
    air = number("air_fraction", "", default=0.0, min_value=0.0, max_exclusive=1.0)
    damping = number("damping", f"{units.force}*{units.time}/{length}", default=0.0, min_value=0.0, max_value=1e9)
    initial = t.number("initial_pressure", unit=pressure, required=False, min_value=0.0, max_value=1e9 / P)
    if initial is not None:
        given["initial_pressure"] = t.raw("initial_pressure")
    spec = HLASpec(plunger_diameter=d * L, chamber_volume=volume * L**3, plunger_mass=0.0, spring_rate=rate * F / L,
                   spring_preload=preload * F, gap=gap * L, gap_length=gap_length * L, viscosity=viscosity * MPA_S,
                   supply_pressure=supply * P, check_conductance=check * L**3 / P, crack_pressure=crack * P,
                   bulk_pressures=tuple(p * P for p in pressures), bulk_moduli=tuple(k * P for k in moduli),
                   air_fraction=air, damping=damping * F / L)
    return spec, None if initial is None else initial * P, given


def load_hla(t: Table, units: UnitSystem, members: tuple) -> HLAPlace:
    """The explicit ``[hla]`` table (module doc); ``members``: the spec's members (the named one is checked)."""
    member = t.string("member")
    bars = [m.name for m in members if m.element == "bar" and m.stiffness is not None]
    if member not in bars:
        raise InputError(t.field("member"), member, f"a bar member with a stiffness: one of {', '.join(bars)}")
    sense = t.string("sense", default="compression", choices=tuple(SENSES))
    spec, initial, given = read_data(t, units)
    t.finish()
    frozen = {key: tuple(value) if isinstance(value, list) else value for key, value in given.items()}
    return HLAPlace(spec, member, sense, initial, given=tuple(sorted(frozen.items())))


def dump_hla(place: HLAPlace) -> dict[str, Any]:
    """The ``[hla]`` table of a spec's adjuster (the keys as given)."""
    return {"member": place.member, "sense": place.sense} | {
        key: list(value) if isinstance(value, tuple) else value for key, value in place.given}
