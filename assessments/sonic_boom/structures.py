"""Walls and floors as single-degree oscillators (thesis sections 1.5.1 and 1.6).

Any consistent unit system works; the presets use inch, pound-force,
second (mass in lbf s^2/in, pressure in psi) like the thesis, or metre,
newton, second.

Wall (section 1.5.1): a homogeneous isotropic plate, simply supported on
all edges, base width ``a`` equal to the wall's and a pseudo-height
``b = net area / a`` (openings removed), so that ``a b`` is the wall's net
area. Its fundamental circular frequency is (equation 8)

.. math::

    \\omega = \\pi^2 \\Big(\\frac{1}{a^2} + \\frac{1}{b^2}\\Big)
              \\sqrt{\\frac{D}{\\rho_s}},\\qquad
    D = \\frac{E h^3}{12 (1 - \\nu^2)},

with ``rho_s`` the mass per unit area (surface weight / g).

Floor (section 1.6, tentative): the top floor of a tall building on ``n``
columns fixed at both ends, stiffness ``k = 12 n E I / l^3`` (equation 11),
loaded by ``F = p * l * d`` (storey height times face width, equation 12),
``omega = sqrt(k / M)`` (equation 13).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

from vtool.errors import InputError, RunError


def _positive(name: str, value: float, unit: str = "") -> float:
    if not (math.isfinite(value) and value > 0.0):
        raise InputError(name, value, "> 0", unit)
    return float(value)


def _finite(what: str, compute: Callable[[], float], inputs: str) -> float:
    """``compute()``, or RunError naming the quantity and the inputs that drove it out of range."""
    try:
        value = float(compute())
    except (OverflowError, ZeroDivisionError, ValueError):
        value = math.nan
    if not (math.isfinite(value) and value > 0.0):
        raise RunError(f"{what} is not a finite positive number (check {inputs})")
    return value


def flexural_rigidity(E: float, h: float, nu: float) -> float:
    """``D = E h^3 / (12 (1 - nu^2))``."""
    _positive("youngs_modulus", E)
    _positive("thickness", h)
    if not (math.isfinite(nu) and -1.0 < nu < 0.5):
        raise InputError("poisson_ratio", nu, "in (-1, 0.5)")
    return _finite("flexural rigidity D", lambda: E * h**3 / (12.0 * (1.0 - nu * nu)),
                   "youngs_modulus, thickness, poisson_ratio")


def pseudo_height(net_area: float, base_width: float) -> float:
    """The thesis' rule: ``b = net area / a``."""
    _positive("net_area", net_area)
    _positive("base_width", base_width)
    return _finite("pseudo-height", lambda: net_area / base_width, "net_area, base_width")


def plate_omega(a: float, b: float, D: float, mass_per_area: float) -> float:
    """Fundamental circular frequency (rad/s) of a simply supported plate, equation 8."""
    _positive("base_width", a)
    _positive("height", b)
    _positive("flexural rigidity", D)
    _positive("mass per unit area", mass_per_area)
    return _finite("plate frequency",
                   lambda: math.pi**2 * (1.0 / a**2 + 1.0 / b**2) * math.sqrt(D / mass_per_area),
                   "base_width, net_area or height, thickness, youngs_modulus, surface_weight")


def floor_stiffness(columns: int, E: float, I: float, l: float) -> float:
    """``k = 12 n E I / l^3`` for ``n`` columns fixed at both ends (equation 11)."""
    if columns < 1:
        raise InputError("columns", columns, ">= 1")
    _positive("youngs_modulus", E)
    _positive("moment_of_inertia", I)
    _positive("storey_height", l)
    return _finite("column stiffness k", lambda: 12.0 * columns * E * I / l**3,
                   "columns, youngs_modulus, moment_of_inertia, storey_height")


@dataclass(frozen=True)
class WallOscillator:
    """A wall per unit area: mass per unit area and fundamental circular frequency."""

    mass_per_area: float
    omega: float

    @property
    def frequency(self) -> float:
        return self.omega / (2.0 * math.pi)


@dataclass(frozen=True)
class FloorOscillator:
    """A floor: mass ``M``, stiffness ``k`` and loaded area ``l * d``."""

    mass: float
    stiffness: float
    loaded_area: float

    @property
    def omega(self) -> float:
        return math.sqrt(self.stiffness / self.mass)

    @property
    def frequency(self) -> float:
        return self.omega / (2.0 * math.pi)
