"""Damage and annoyance criteria as data, and the boom pressure each one allows.

A :class:`Criterion` limits one peak response of the oscillator:

* ``response = "velocity"``: the transient peak velocity (the thesis' damage
  threshold, 4.5 in/s, and safe limit, 2 in/s, section 1.5);
* ``response = "displacement"``: the transient peak displacement, compared
  (tentatively, as the thesis does in section 1.6) with a steady-state
  limit. A steady-state limit given as a velocity ``v`` or an acceleration
  ``a`` is turned into a displacement amplitude at the oscillator's
  frequency ``f``: ``x = v / (2 pi f)`` or ``x = a / (2 pi f)^2``.

The allowed peak overpressure follows from the DAF (equations 6, 7, 15):
with ``x_s = p * S`` the static deflection under pressure ``p``
(``S = 1/(m omega^2)`` for a wall per unit area, ``S = l d / k`` for a
floor),

.. math::

    p^+ = \\frac{v_{lim}}{\\mathrm{DAF}_v\\, S\\, \\omega}
    \\quad\\text{or}\\quad
    p^+ = \\frac{x_{lim}}{\\mathrm{DAF}_x\\, S}.

Users add their own criteria in a preset (``[[criteria]]`` tables with the
same fields as :class:`Criterion`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from vtool.errors import InputError

#: metres per unit of each accepted criterion unit, and its kind.
UNITS: dict[str, tuple[float, str]] = {
    "in/s": (0.0254, "velocity"),
    "mm/s": (1e-3, "velocity"),
    "m/s": (1.0, "velocity"),
    "in": (0.0254, "displacement"),
    "mm": (1e-3, "displacement"),
    "m": (1.0, "displacement"),
    "g": (9.80665, "acceleration"),
    "in/s^2": (0.0254, "acceleration"),
    "m/s^2": (1.0, "acceleration"),
}
RESPONSES: tuple[str, ...] = ("velocity", "displacement")


@dataclass(frozen=True)
class Criterion:
    """A limit on a peak response. ``f_min``/``f_max`` (Hz) bound its validity."""

    name: str
    source: str
    response: str
    value: float
    unit: str
    tentative: bool = False
    f_min: float | None = None
    f_max: float | None = None

    def check(self, field: str = "criteria") -> Criterion:
        if self.response not in RESPONSES:
            raise InputError(f"{field}.response", self.response, f"one of: {', '.join(RESPONSES)}")
        if self.unit not in UNITS:
            raise InputError(f"{field}.unit", self.unit, f"one of: {', '.join(UNITS)}")
        kind = UNITS[self.unit][1]
        if self.response == "velocity" and kind != "velocity":
            raise InputError(f"{field}.unit", self.unit,
                             "a velocity unit (in/s, mm/s, m/s) for a velocity criterion")
        if not (math.isfinite(self.value) and self.value > 0.0):
            raise InputError(f"{field}.value", self.value, "> 0", self.unit)
        for key in ("f_min", "f_max"):
            bound = getattr(self, key)
            if bound is not None and not (math.isfinite(bound) and bound >= 0.0):
                raise InputError(f"{field}.{key}", bound, ">= 0", "Hz")
        return self

    def limit(self, frequency_hz: np.ndarray | float, metres_per_length: float) -> np.ndarray:
        """Limit on the response quantity at ``frequency_hz``, in the preset's length unit."""
        scale, kind = UNITS[self.unit]
        value = self.value * scale / metres_per_length
        omega = 2.0 * math.pi * np.asarray(frequency_hz, dtype=float)
        if self.response == "velocity" or kind == "displacement":
            return value * np.ones_like(omega)
        if kind == "velocity":
            return value / omega
        return value / omega**2

    def in_range(self, frequency_hz: float) -> bool:
        return (self.f_min is None or frequency_hz >= self.f_min) and (
            self.f_max is None or frequency_hz <= self.f_max)

    @property
    def quantity(self) -> str:
        """The quantity the value limits, by its unit: velocity, displacement or acceleration."""
        return UNITS[self.unit][1]

    def rule(self) -> str:
        """The limit with the quantity it bounds and its unit, then how it is applied.

        ``peak velocity <= 4.5 in/s``; a steady-state velocity or acceleration
        limit read on the displacement: ``velocity <= 0.04 in/s, applied as peak
        displacement <= 0.04 in/s / (2 pi f)``.
        """
        head = f"{self.quantity} <= {self.value:g} {self.unit}"
        if self.response == self.quantity:
            return f"peak {head}"
        power = "" if self.quantity == "velocity" else "^2"
        return (f"steady-state {head}, applied as peak {self.response} <= "
                f"{self.value:g} {self.unit} / (2 pi f){power}")

    def describe(self) -> str:
        tag = " [tentative]" if self.tentative else ""
        band = ""
        if self.f_min is not None or self.f_max is not None:
            band = f", {self.f_min or 0:g}-{self.f_max if self.f_max is not None else 'inf'} Hz"
        return f"{self.name}: {self.rule()}{band}{tag} ({self.source})"


#: Built-in criteria. The first two are the thesis' (section 1.5); the
#: Reiher-Meister rows are steady-state perception zones read from the
#: classic chart as constant velocity (or acceleration) lines, and are only
#: tentative for transient boom response (thesis section 1.6; its own
#: Figure 7 values are lost in the OCR).
BUILTIN: dict[str, Criterion] = {
    c.name: c
    for c in (
        Criterion("damage-threshold",
                  "Edwards & Northwood via thesis sec. 1.5: blasting damage threshold",
                  "velocity", 4.5, "in/s"),
        Criterion("safe-limit", "thesis sec. 1.5, eq. 7 (its ref. 23): recommended safe limit",
                  "velocity", 2.0, "in/s"),
        Criterion("reiher-meister-perceptible",
                  "Reiher & Meister (1931) steady-state chart: just perceptible ~0.04 in/s",
                  "displacement", 0.04, "in/s", tentative=True, f_min=5.0, f_max=100.0),
        Criterion("reiher-meister-annoying",
                  "Reiher & Meister (1931) steady-state chart: annoying from ~0.1 in/s",
                  "displacement", 0.1, "in/s", tentative=True, f_min=5.0, f_max=100.0),
        Criterion("reiher-meister-unpleasant",
                  "Reiher & Meister (1931) steady-state chart: unpleasant at ~0.1 g",
                  "displacement", 0.1, "g", tentative=True, f_min=5.0, f_max=100.0),
    )
}


def allowable_pressure(criterion: Criterion, daf: np.ndarray | float, frequency_hz: np.ndarray | float,
                       static_per_pressure: np.ndarray | float, metres_per_length: float
                       ) -> np.ndarray:
    """Peak boom overpressure that just reaches the criterion.

    ``daf`` is the DAF of the criterion's response quantity;
    ``static_per_pressure`` the static deflection per unit pressure (``S``
    above), in the preset's units.
    """
    daf = np.asarray(daf, dtype=float)
    f = np.asarray(frequency_hz, dtype=float)
    lim = criterion.limit(f, metres_per_length)
    S = np.asarray(static_per_pressure, dtype=float)
    with np.errstate(divide="ignore"):
        if criterion.response == "velocity":
            return lim / (daf * S * 2.0 * math.pi * f)
        return lim / (daf * S)
