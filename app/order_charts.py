"""Terminal chart of a cam-order spectrum (:mod:`vtool.solvers.studies.orders`): amplitude against cam order,
the natural frequencies of the visited configurations marked as orders (ω_n / ω). The data, its table and the
dominant orders near each natural frequency live below app/ (vtool.solvers.studies.orders); this module
only draws."""

from __future__ import annotations

import numpy as np

from vtool.app.plots import line_chart
from vtool.solvers.studies.orders import Spectrum


def order_chart(spectrum: Spectrum, frequencies: list[tuple[str, float]], *, highest: float | None = None,
                width: int = 100, height: int = 20, color: bool = True) -> str:
    """Amplitude per cam order as a staircase up to ``highest`` (default: past the highest natural frequency
    in orders, at most the Nyquist order), with a line at each natural frequency's order."""
    from vtool.presets.charts import order_chart as order_data

    cam_hz = spectrum.rpm / 60.0
    data = order_data(spectrum, frequencies, highest)  # the figure's series and its range of orders
    x, y = data.panels[0].curves[0].x, data.panels[0].curves[0].y
    top = data.xlim[1] if data.xlim else float(x[-1])
    series = {f"{spectrum.quantity} ({spectrum.unit})": y}
    peak = float(y.max()) if len(y) else 1.0
    for label, hz in frequencies:
        order = hz / cam_hz
        if order <= top:  # a vertical mark: the spectrum's top at that order's nearest bin, zero elsewhere
            line = np.zeros_like(y)
            line[int(np.argmin(np.abs(x - order)))] = peak
            series[f"natural frequency {hz:.0f} Hz ({label}): order {order:.2f}"] = line
    return line_chart(x, series, title=f"{spectrum.quantity}: amplitude per cam order at {spectrum.rpm:g} rev/min",
                      xlabel="cam order", ylabel=spectrum.unit, width=width, height=height, color=color, step=True)
