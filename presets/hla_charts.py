"""Chart data of a run with a hydraulic lash adjuster (issue 41): chamber pressure and pump-up.

:func:`hla_charts` turns :func:`vtool.solvers.studies.hla.hla_series` (a run of a
preset with ``[hla]`` / ``[train.hla]``) into :class:`vtool.chart.Chart` data:
the chamber pressure and the plunger's extension against cam angle over the
run, and the pump-up, the plunger's extension at the run's start (0) and at
each base circle (1, 2, ...) and its drift from the base circle before. ``app/`` draws them
(``--figure``, docs/torque.md's figures by benchmarks/docs_figures.py).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from vtool.chart import Chart, Panel, curve, with_unit

CAM_ANGLE = "cam angle (deg)"


def hla_charts(series: Any, title: str) -> list[Chart]:
    """[chamber pressure and plunger extension against cam angle, pump-up per cycle] (module doc)."""
    units, columns = series.units, series.columns
    pressure = Chart(f"HLA chamber pressure ({units['hla_pressure']})", CAM_ANGLE, (
        Panel((curve("chamber pressure", series.cam_angle, columns["hla_pressure"]),),
              with_unit("chamber pressure", units["hla_pressure"])),
        Panel((curve("plunger extension", series.cam_angle, columns["hla_plunger_extension"]),),
              with_unit("plunger extension", units["hla_plunger_extension"]))), title)
    length = series.length_unit
    start = float(columns["hla_plunger_extension"][0]) if len(series.cam_angle) else 0.0
    extension = np.asarray(series.cycles["extension"], dtype=float)
    marks = np.arange(1, len(extension) + 1, dtype=float)
    drift = np.asarray(series.cycles["drift"], dtype=float)
    panels = [Panel((curve("extension: at the start (0), then at each base circle", np.append(0.0, marks),
                           np.append(start, extension)),), with_unit("plunger extension", length))]
    if len(drift):
        panels.append(Panel((curve("drift from the base circle before", marks[1:], drift),),
                            with_unit("drift per cycle", length)))
    pump = Chart(f"HLA pump-up: extension at each base circle ({length})", "base circle (cam revolution)",
                 tuple(panels), title)
    return [pressure, pump]
