"""An HLA run's series for figures and tables: chamber pressure against cam angle, and pump-up cycle by cycle.

:func:`hla_series` reads a trace of a preset with an adjuster (``[hla]`` or
``[train.hla]``, run on a back end that takes nonlinear elements) and returns
the rows' cam angle, chamber pressure, plunger extension, adjuster force and
the check-valve and gap flows, each with its unit, and the per-cycle figures of
:func:`vtool.solvers.model.hla.per_cycle` (the plunger's extension at each base
circle, its drift, travel, leak-down and pump-in). Drawing is app/'s.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from vtool.solvers.model.attached import elements_of
from vtool.solvers.model.hla import HLAElement, per_cycle
from vtool.solvers.trace import Trace


@dataclass(frozen=True)
class HLASeries:
    """Row series (``columns``: name -> values, ``units``: name -> unit) and the per-cycle figures."""

    cam_angle: np.ndarray  # deg
    columns: dict[str, np.ndarray]  # hla_pressure, hla_plunger_extension, hla_force, hla_check_flow, hla_leak_flow
    units: dict[str, str]
    cycles: dict  # per_cycle(): base_circle_angle, extension, drift, travel, leak_down, pump_in, valve_lift
    length_unit: str


def hla_series(trace: Trace) -> HLASeries:
    """The HLA series of a run (module doc); KeyError if the trace has no adjuster's states."""
    if trace.states is None:
        raise KeyError("hla: the trace has no nonlinear-element states (a preset with [hla], run on scipy)")
    elements = elements_of(trace.spec)
    for element, part in zip(elements.elements, elements.slices, strict=True):
        if isinstance(element, HLAElement):
            n = trace.spec.n_coordinates
            s = trace.states[:, part].T
            rows = element.columns(trace.time, trace.q[:, :n].T, trace.qd[:, :n].T, s)
            return HLASeries(trace.cam_angle, {name: values for name, _, values in rows},
                             {name: unit for name, unit, _ in rows}, per_cycle(element, trace, s),
                             trace.spec.unit_system.length)
    raise KeyError("hla: the preset has no adjuster")
