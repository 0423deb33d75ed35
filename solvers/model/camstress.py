"""Cam-follower contact stress: Hertz line contact and the elastohydrodynamic film.

Line contact (a roller or a flat face on the cam, Johnson, *Contact
Mechanics*, 1985, §4.3): with the normal force F on a contact length L, the
effective radius 1/R* = 1/ρ_cam + 1/r_roller (a flat face: 1/R* = 1/ρ_cam) and
the contact modulus 1/E* = (1 - ν₁²)/E₁ + (1 - ν₂²)/E₂,

    p₀ = √(F E* / (π L R*)),   b = √(4 F R* / (π L E*))   (peak pressure, half-width).

Minimum oil-film thickness by Dowson and Higginson's line-contact formula
(Dowson & Higginson, *Elasto-hydrodynamic Lubrication*, 1977; Hamrock,
*Fundamentals of Fluid Film Lubrication*, eq. 21.62):

    h_min / R* = 2.65 U^0.70 G^0.54 W^-0.13,
    U = η₀ u / (E' R*),  G = α E',  W = (F/L) / (E' R*),  E' = 2 E*,

η₀ the oil's viscosity at the inlet, α its pressure-viscosity coefficient
and u the entraining (mean surface) velocity relative to the contact from
the kinematics (:mod:`vtool.solvers.model.camshape`; a flat face's goes
through zero on the flanks, where the formula gives no film: the squeeze
film that carries the load there is not modelled). The formula is
isothermal and fully flooded; it is a lower-bound design figure, not a
prediction of failure.

At every output row of a run, the model's cam-contact force and the cam
angle give the normal force, R* and u by linear interpolation in a table of
one revolution (:data:`TABLE_POINTS` angles; curvature 1/R*, not R*, is
interpolated: it stays finite through a flank's inflection).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from vtool.solvers.model.camshape import Contact, contact
from vtool.solvers.model.spec import CamSpec, FollowerSpec, MechanismSpec

TABLE_POINTS = 7200  # one revolution, every 0.05 degree
DH_COEFFICIENT = 2.65


def contact_modulus(E1: float, nu1: float, E2: float, nu2: float) -> float:
    """E* = 1 / ((1 - ν₁²)/E₁ + (1 - ν₂²)/E₂)."""
    return 1.0 / ((1.0 - nu1**2) / E1 + (1.0 - nu2**2) / E2)


def hertz_line(force: np.ndarray, length: float, radius: np.ndarray, modulus: float) -> tuple[np.ndarray, np.ndarray]:
    """Peak pressure p₀ and half-width b of a line contact (0 where F <= 0 or R* is not positive)."""
    force = np.asarray(force, dtype=float)
    radius = np.asarray(radius, dtype=float)
    loaded = (force > 0.0) & (radius > 0.0) & np.isfinite(radius)
    F = np.where(loaded, force, 0.0)
    R = np.where(loaded, radius, 1.0)
    return (np.sqrt(F * modulus / (math.pi * length * R)), np.sqrt(4.0 * F * R / (math.pi * length * modulus)))


def film_thickness(force: np.ndarray, length: float, radius: np.ndarray, modulus: float, entraining: np.ndarray,
                   viscosity: float, pressure_viscosity: float) -> np.ndarray:
    """Dowson-Higginson minimum film thickness (module doc); 0 where there is no load, no R* or no entrainment."""
    force, radius, u = (np.asarray(x, dtype=float) for x in (force, radius, entraining))
    E = 2.0 * modulus
    ok = (force > 0.0) & (radius > 0.0) & np.isfinite(radius) & (u > 0.0)
    R = np.where(ok, radius, 1.0)
    U = viscosity * np.where(ok, u, 1.0) / (E * R)
    W = np.where(ok, force, 1.0) / length / (E * R)
    G = pressure_viscosity * E
    return np.where(ok, DH_COEFFICIENT * R * U**0.70 * G**0.54 * W**-0.13, 0.0)


@dataclass(frozen=True)
class StressTable:
    """Per-revolution contact data of a spec (see :func:`stress_table`)."""

    angles_deg: np.ndarray
    curvature: np.ndarray  # 1/R*
    force_factor: np.ndarray
    entraining_per_omega: np.ndarray
    modulus: float  # E*
    length: float
    viscosity: float | None  # in the preset's pressure unit x s
    pressure_viscosity: float | None  # per pressure unit


@lru_cache(maxsize=16)
def stress_table(spec: MechanismSpec) -> StressTable:
    """The contact data of one revolution, in the preset's units."""
    follower = spec.follower
    assert follower is not None
    c = revolution(follower, spec.lift_law)
    units = spec.unit_system
    oil = follower.oil
    return StressTable(
        c.cam_angle_deg, c.curvature, c.force_factor, c.entraining_per_omega, modulus_of(follower),
        follower.width,
        None if oil is None else oil.viscosity / units.pascals_per_pressure,
        None if oil is None else oil.pressure_viscosity * units.pascals_per_pressure)


def modulus_of(follower: FollowerSpec) -> float:
    return contact_modulus(follower.cam_modulus, follower.cam_poisson, follower.follower_modulus,
                           follower.follower_poisson)


def _periodic(table: StressTable, values: np.ndarray, angles_deg: np.ndarray) -> np.ndarray:
    return np.interp(np.mod(angles_deg, 360.0), table.angles_deg, values, period=360.0)


def stress_rows(spec: MechanismSpec, cam_angle_deg: np.ndarray, model_force: np.ndarray) -> dict[str, np.ndarray]:
    """Normal force, p₀, half-width and (with an oil) film thickness at output rows."""
    table = stress_table(spec)
    omega = spec.run.omega
    angles = np.asarray(cam_angle_deg, dtype=float)
    curvature = _periodic(table, table.curvature, angles)
    with np.errstate(divide="ignore"):
        radius = np.where(curvature > 0.0, 1.0 / curvature, np.inf)
    normal = np.asarray(model_force, dtype=float) * _periodic(table, table.force_factor, angles)
    p0, b = hertz_line(normal, table.length, radius, table.modulus)
    rows = {"normal_force": normal, "contact_pressure": p0, "half_width": b}
    if table.viscosity is not None:
        u = omega * _periodic(table, table.entraining_per_omega, angles)
        rows["film_thickness"] = film_thickness(normal, table.length, radius, table.modulus, u,
                                                table.viscosity, table.pressure_viscosity or 0.0)
    return rows


#: CSV/summary names of the row quantities and their unit kinds
ROW_UNITS = {"normal_force": "force", "contact_pressure": "pressure", "half_width": "length",
             "film_thickness": "length"}


def row_unit(spec: MechanismSpec, name: str) -> str:
    units = spec.unit_system
    return {"force": units.force, "pressure": units.pressure, "length": units.length}[ROW_UNITS[name]]


def stress_summary(spec: MechanismSpec, cam_angle_deg: np.ndarray, model_force: np.ndarray) -> dict:
    """Cycle extremes of the contact stress at the output rows (rows of the first revolution included).

    ``max_contact_pressure`` and its angle; ``max_half_width``; with an oil
    the smallest film thickness while loaded and its angle. Also the cam's
    smallest radius of curvature and largest pressure angle over a revolution.
    """
    units = spec.unit_system
    rows = stress_rows(spec, cam_angle_deg, model_force)
    p = rows["contact_pressure"]
    result: dict = {"pressure_unit": units.pressure, "length_unit": units.length, "force_unit": units.force,
                    "rows": int(len(p)), "at": "output rows"}
    if len(p):
        i = int(np.argmax(p))
        result.update(max_contact_pressure=float(p[i]), max_contact_pressure_angle_deg=float(cam_angle_deg[i]),
                      max_normal_force=float(rows["normal_force"].max()),
                      max_half_width=float(rows["half_width"].max()))
        if "film_thickness" in rows:
            loaded = rows["normal_force"] > 0.0
            h = np.where(loaded, rows["film_thickness"], np.inf)
            j = int(np.argmin(h))
            result.update(min_film_thickness=float(h[j]) if np.isfinite(h[j]) else None,
                          min_film_thickness_angle_deg=float(cam_angle_deg[j]))
    c = revolution(spec.follower, spec.lift_law)
    result.update(min_cam_curvature_radius=float(np.min(c.curvature_radius)),
                  max_pressure_angle_deg=float(np.max(np.abs(c.pressure_angle_deg))))
    return result


@lru_cache(maxsize=16)
def revolution(follower: FollowerSpec, law: CamSpec) -> Contact:
    """The contact over one revolution (:data:`TABLE_POINTS` angles), computed once per follower and law."""
    return contact(follower, law, np.linspace(0.0, 2.0 * math.pi, TABLE_POINTS, endpoint=False))


def stress_text(s: dict) -> list[str]:
    """Summary lines of :func:`stress_summary`'s dict."""
    p, u = s["pressure_unit"], s["length_unit"]
    lines = [""]
    if "max_contact_pressure" in s:
        lines.append(f"cam contact (Hertz line contact, at the {s['at']}): max pressure "
                     f"{s['max_contact_pressure']:.5g} {p} at {s['max_contact_pressure_angle_deg']:.1f} deg, "
                     f"max half-width {s['max_half_width']:.4g} {u}, max normal force "
                     f"{s['max_normal_force']:.5g} {s['force_unit']}")
    if "min_film_thickness" in s:
        h = s["min_film_thickness"]
        lines.append("oil film (Dowson-Higginson): " + ("no loaded row" if h is None else
                     f"min {h:.4g} {u} at {s['min_film_thickness_angle_deg']:.1f} deg"))
    lines.append(f"cam: smallest radius of curvature {s['min_cam_curvature_radius']:.5g} {u}, "
                 f"largest pressure angle {s['max_pressure_angle_deg']:.3g} deg")
    return lines
