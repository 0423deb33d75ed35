"""The nonlinear elements a valve-train spec attaches to its chain (:mod:`vtool.solvers.model.nonlinear`)."""

from __future__ import annotations

from typing import Any

from vtool.solvers.model.nonlinear import ElementSet, NonlinearElement


def elements_of(spec: Any) -> ElementSet:
    """The spec's nonlinear elements: its HLA (``[hla]``), then its valve forces (guide friction, gas)."""
    found: list[NonlinearElement] = []
    if getattr(spec, "hla", None) is not None:
        from vtool.solvers.model.hla import HLAElement

        found.append(HLAElement(spec))
    valve_forces = getattr(spec, "valve_forces", None)
    if valve_forces is not None and valve_forces.active:
        from vtool.solvers.model.valveforces import ValveForceElement

        found.append(ValveForceElement(spec))
    return ElementSet(tuple(found))
