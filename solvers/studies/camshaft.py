"""Several valve trains on one camshaft: each valve's drive torque shifted by its phase and summed.

A valve's cam lobe is its train's cam turned by its phase φ (cam deg): the
lobe reaches the train's cam angle θ when the camshaft is at θ + φ, so its
torque on the camshaft is T(θ - φ). The camshaft's torque is the sum over
the valves, each T taken from its train's run over one whole cam revolution
(:func:`vtool.solvers.studies.torque.torque_rows`) on an even grid of cam
angle (the trains' output interval; rows between are interpolated linearly,
periodic in 360 deg). Cylinders' phases follow the firing order: the k-th
cylinder fired (k = 0, 1, ...) runs 720 k / n crank deg = 360 k / n cam deg
after the first, plus a valve's own offset (an exhaust lobe's, in cam deg).

The summed torque's orders are the discrete Fourier series over the
revolution (:func:`vtool.solvers.studies.orders.series_spectrum`): n
identical valves evenly phased cancel every order that is not a multiple of
n, which the tests check.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from vtool.errors import InputError
from vtool.solvers.studies.orders import Spectrum, series_spectrum

REVOLUTION = 360.0


def cylinder_phases(cylinders: int, firing_order: tuple[int, ...]) -> dict[int, float]:
    """Cam-degree phase of each cylinder (1-based number) from the firing order (module doc)."""
    if sorted(firing_order) != list(range(1, cylinders + 1)):
        raise InputError("camshaft.firing_order", list(firing_order),
                         f"each cylinder 1..{cylinders} once (the order in which they fire)")
    return {cylinder: REVOLUTION * k / cylinders for k, cylinder in enumerate(firing_order)}


def periodic_series(cam_angle_deg: np.ndarray, values: np.ndarray, grid: np.ndarray) -> np.ndarray:
    """Rows of one revolution interpolated at ``grid`` (deg), periodic in 360 deg."""
    angle = np.mod(np.asarray(cam_angle_deg, dtype=float), REVOLUTION)
    order = np.argsort(angle, kind="stable")
    angle, first = np.unique(angle[order], return_index=True)
    return np.interp(np.mod(grid, REVOLUTION), angle, np.asarray(values, dtype=float)[order][first],
                     period=REVOLUTION)


@dataclass(frozen=True)
class CamshaftTorque:
    """The camshaft's summed drive torque over one revolution and each valve's share."""

    cam_angle_deg: np.ndarray  # the even grid, 0 <= θ < 360
    valves: tuple[str, ...]  # the valves' labels
    phases_deg: np.ndarray
    valve_torque: np.ndarray  # (valves, grid): each valve's torque on the camshaft
    torque: np.ndarray  # their sum
    unit: str
    rpm: float

    @property
    def step(self) -> float:
        return float(self.cam_angle_deg[1] - self.cam_angle_deg[0])

    def spectrum(self) -> Spectrum:
        return series_spectrum("camshaft_torque", self.unit, np.append(self.cam_angle_deg, REVOLUTION),
                               np.append(self.torque, self.torque[0]), 0.0, 1, self.step, self.rpm)

    def summary(self) -> dict:
        t = self.torque
        return {"torque_unit": self.unit, "rpm": self.rpm, "valves": len(self.valves),
                "mean_torque": float(t.mean()), "max_torque": float(t.max()), "min_torque": float(t.min()),
                "max_torque_angle_deg": float(self.cam_angle_deg[int(np.argmax(t))]),
                "peak_to_peak_torque": float(t.max() - t.min()),
                "orders": [{"order": order, "amplitude": amplitude} for order, amplitude in self.spectrum().top(8)]}


def sum_valves(labels: list[str], series: list[tuple[np.ndarray, np.ndarray]], phases_deg: list[float],
               step_deg: float, unit: str, rpm: float) -> CamshaftTorque:
    """Each valve's torque rows (cam angle deg, torque over one revolution of its train) at camshaft angle θ
    as T(θ - φ), and their sum, on a grid every ``step_deg``."""
    count = int(round(REVOLUTION / step_deg))
    grid = np.arange(count) * (REVOLUTION / count)
    shares = np.array([periodic_series(angle, torque, grid - phase)
                       for (angle, torque), phase in zip(series, phases_deg, strict=True)])
    return CamshaftTorque(grid, tuple(labels), np.asarray(phases_deg, dtype=float), shares, shares.sum(axis=0), unit,
                          rpm)


def camshaft_text(result: CamshaftTorque) -> str:
    """The summary as lines: the torque's mean, extremes and largest orders."""
    s = result.summary()
    u = s["torque_unit"]
    lines = [f"camshaft: {s['valves']} valves at {s['rpm']:g} cam rev/min",
             f"drive torque: mean {s['mean_torque']:.5g} {u}, {s['min_torque']:.5g} .. {s['max_torque']:.5g} {u} "
             f"(peak-to-peak {s['peak_to_peak_torque']:.5g} {u}, largest at {s['max_torque_angle_deg']:.1f} deg)",
             f"each valve's torque ({u}); phase in cam deg:",
             f"{'valve':<24} {'phase':>7} {'mean':>10} {'max':>10} {'min':>10} {'peak-peak':>10}"]
    for label, phase, share in zip(result.valves, result.phases_deg, result.valve_torque, strict=True):
        lines.append(f"{label[:24]:<24} {phase:>7.2f} {share.mean():>10.5g} {share.max():>10.5g} {share.min():>10.5g} "
                     f"{share.max() - share.min():>10.5g}")
    lines.append(result.spectrum().table(8))
    return "\n".join(lines)


def camshaft_csv_text(result: CamshaftTorque) -> str:
    """The grid's rows: cam angle, each valve's torque and the sum."""
    from vtool.csvrows import csv_text

    u = result.unit
    header = ["cam_angle (deg)"] + [f"{label} torque ({u})" for label in result.valves] + [f"camshaft_torque ({u})"]
    rows = [[f"{a:.10g}"] + [f"{v:.10g}" for v in shares] + [f"{t:.10g}"]
            for a, shares, t in zip(result.cam_angle_deg, result.valve_torque.T, result.torque, strict=True)]
    return csv_text([header] + rows)
