"""Nonlinear elements: extra first-order states and forces on coordinates, from (t, q, v, states).

The valve train between events is linear (:mod:`vtool.solvers.exact.piecewise`).
A nonlinear element adds to it, in the model's units,

* ``states``: first-order states s of its own (an HLA's chamber pressure), with
  rates ṡ = r(t, q, q̇, s);
* ``forces``: a force f(t, q, q̇, s) on some of the full model coordinates
  (positive along the coordinate), added to the right-hand side:
  M q̈ + C q̇ + K q = … + f.

Both are evaluated on the full coordinates q, q̇ (every model coordinate, the
sources' not included), for one instant (vectors, s of shape (ns,)) or for many
(columns: q of shape (n, nt), s of shape (ns, nt)); a back end that takes
elements adds f to its accelerations through the configuration's mass matrix,
adds f's share to the closed rigid contacts' forces, and integrates s beside
its state. A back end class says that it does with the registry flag
``nonlinear_elements`` (:mod:`vtool.solvers.backends`); the others refuse a
preset with elements in one line naming the field and the back ends that run it.

What an element reports: output columns per row (name, unit, values),
discrete events (name, time) found on its state rows, and a summary
dictionary (numbers with ``*_unit`` keys) and its text lines.

:func:`vtool.solvers.model.attached.elements_of` builds a spec's elements
(the HLA of ``[hla]``, :mod:`vtool.solvers.model.hla`; the valve's guide
friction and gas force, :mod:`vtool.solvers.model.valveforces`);
:func:`element_fields` names them without building them.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass
from typing import Any

import numpy as np


class NonlinearElement(ABC):
    """One nonlinear element (module doc). Subclasses set :attr:`field`, :attr:`state_names` and
    :attr:`state_units` and implement :meth:`initial` and :meth:`evaluate`."""

    #: the preset field that introduced the element (named in a back end's refusal)
    field: str = ""
    #: its entry's key in the run's summary (and JSON)
    key: str = ""
    #: its states' names and units (may be empty: a force without a state, e.g. friction)
    state_names: tuple[str, ...] = ()
    state_units: tuple[str, ...] = ()

    @property
    def size(self) -> int:
        return len(self.state_names)

    @abstractmethod
    def initial(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """The states at a static start with coordinates q and velocities v."""

    @abstractmethod
    def evaluate(self, t: float | np.ndarray, q: np.ndarray, v: np.ndarray,
                 s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(f, ṡ): the force on every full coordinate (shape of q) and the states' rates (shape of s)."""

    def columns(self, t: np.ndarray, q: np.ndarray, v: np.ndarray, s: np.ndarray) -> list[tuple[str, str, np.ndarray]]:
        """Output columns on rows (q, v: (n, nt); s: (ns, nt)): (name, unit, values) each (default: states)."""
        return [(name, unit, s[i]) for i, (name, unit) in enumerate(zip(self.state_names, self.state_units,
                                                                           strict=True))]

    def summary(self, trace: Any, s: np.ndarray) -> dict[str, Any]:
        """Numbers for the run's summary (``*_unit`` keys), from the trace and the states' rows (ns, nt)."""
        return {}

    def summary_text(self, entry: dict[str, Any]) -> list[str]:
        """Lines of the summary text for :meth:`summary`'s entry."""
        return []


@dataclass(frozen=True)
class ElementSet:
    """A spec's elements side by side: their states stacked in one vector (``slices``)."""

    elements: tuple[NonlinearElement, ...]

    @property
    def size(self) -> int:
        return sum(e.size for e in self.elements)

    @property
    def slices(self) -> list[slice]:
        out, start = [], 0
        for e in self.elements:
            out.append(slice(start, start + e.size))
            start += e.size
        return out

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(name for e in self.elements for name in e.state_names)

    @property
    def units(self) -> tuple[str, ...]:
        return tuple(unit for e in self.elements for unit in e.state_units)

    def initial(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        parts = [np.asarray(e.initial(q, v), dtype=float) for e in self.elements]
        return np.concatenate(parts) if parts else np.zeros(0)

    def evaluate(self, t: float | np.ndarray, q: np.ndarray, v: np.ndarray,
                 s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The summed forces on the coordinates and the stacked rates (vectors or columns)."""
        if len(self.elements) == 1:
            return self.elements[0].evaluate(t, q, v, s)
        force = np.zeros(np.shape(q))
        rates = np.zeros(np.shape(s))
        for e, part in zip(self.elements, self.slices, strict=True):
            f, r = e.evaluate(t, q, v, s[part])
            force += f
            rates[part] = r
        return force, rates


def element_fields(spec: Any) -> tuple[str, ...]:
    """The preset fields of a spec's nonlinear elements (nothing built: for a back end's refusal)."""
    fields = []
    if getattr(spec, "hla", None) is not None:
        fields.append("hla")
    valve_forces = getattr(spec, "valve_forces", None)
    if valve_forces is not None and valve_forces.active:
        fields.append(valve_forces.field)
    return tuple(fields)
