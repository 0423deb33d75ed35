"""Terminal chart of a cam-order spectrum (:mod:`vtool.solvers.studies.orders`): amplitude against cam order,
the natural frequencies of the visited configurations marked as orders (ω_n / ω), and the dominant orders
near each listed under the chart. The data and its table live below app/; this module only draws."""

from __future__ import annotations

import numpy as np

from vtool.app.plots import line_chart
from vtool.solvers.studies.orders import Spectrum, dominant_near


def order_chart(spectrum: Spectrum, frequencies: list[tuple[str, float]], *, highest: float | None = None,
                width: int = 100, height: int = 20, color: bool = True) -> str:
    """Amplitude per cam order as a staircase up to ``highest`` (default: past the highest natural frequency
    in orders, at most the Nyquist order), with a line at each natural frequency's order; then the dominant
    orders near each natural frequency."""
    from vtool.presets.charts import order_chart as order_data

    cam_hz = spectrum.rpm / 60.0
    data = order_data(spectrum, frequencies, highest)  # the figure's series and its range of orders
    x, y = data.panels[0].curves[0].x, data.panels[0].curves[0].y
    top = float(x[-1]) if len(x) else 0.0
    series = {f"{spectrum.quantity} ({spectrum.unit})": y}
    peak = float(y.max()) if len(y) else 1.0
    for label, hz in frequencies:
        order = hz / cam_hz
        if order <= top:  # a vertical mark: the spectrum's top at that order's nearest bin, zero elsewhere
            line = np.zeros_like(y)
            line[int(np.argmin(np.abs(x - order)))] = peak
            series[f"natural frequency {hz:.0f} Hz ({label}): order {order:.2f}"] = line
    chart = line_chart(x, series, title=f"{spectrum.quantity}: amplitude per cam order at {spectrum.rpm:g} rev/min",
                       xlabel="cam order", ylabel=spectrum.unit, width=width, height=height, color=color, step=True)
    lines = [chart, "dominant orders near each natural frequency (within 15 %):"]
    for label, hz, order, best in dominant_near(spectrum, frequencies):
        near = ", ".join(f"order {o:g}: {a:.4g} {spectrum.unit}" for o, a in best) or "none below the Nyquist order"
        lines.append(f"  {hz:9.1f} Hz ({label}, order {order:.2f}): {near}")
    return "\n".join(lines)
