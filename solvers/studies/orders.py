"""Cam-order spectra: any output of a run over its evaluated cycles, in multiples of the cam speed.

Over a window of N whole cam cycles (:func:`vtool.solvers.studies.metrics.evaluation_window`
rounded to whole cycles: a steady run's last cycle, a plain run's whole
revolutions after the first), a quantity y (``q7``, ``q1-q9``, ``F2``: see
:meth:`Trace.quantity <vtool.solvers.trace.Trace.quantity>`) sampled at P
equal cam-angle steps per cycle (the output interval; rows between are
interpolated linearly, events add no rows) has the discrete Fourier series

    y(θ) ≈ c_0 + Σ_k a_k cos(k θ / N) + b_k sin(k θ / N),   θ in deg of cam angle

whose order-j term (j = k / N cam orders: order 1 once per cam revolution)
has the amplitude |Y_k| 2 / (N P) (c_0 for order 0) and the phase of Y_k,
Y = rfft(y). This is exact for a response with no orders above P/2 (the
Nyquist order, 180 at 1 deg rows); higher orders fold back (alias), so a
chattering contact force wants a finer ``output_interval``. A linear
train driven by the thesis' harmonic cam responds at orders 0 and 1 alone.

:func:`dominant_near` lists, for each natural frequency of the active
configurations, the strongest orders within a band about it (ω_n / ω cam
orders): the orders that excite that mode at this speed.
"""

from __future__ import annotations

import dataclasses
import math
import re
from dataclasses import dataclass

import numpy as np

from vtool.errors import InputError
from vtool.solvers.model.configurations import mask_of
from vtool.solvers.model.spec import ENABLED, MechanismSpec
from vtool.solvers.studies.window import REVOLUTION, evaluation_window
from vtool.solvers.trace import Trace


def quantity_unit(spec: MechanismSpec, quantity: str) -> str:
    """The unit of ``q7``, ``q1-q9`` or ``F2`` (a rotation's coordinate: rad)."""
    text = quantity.replace(" ", "")
    if text.startswith("F") or text.endswith("_force"):  # a clearance's force or a spring's end force
        return spec.unit_system.force
    number = int(text[1:].split("-")[0])
    if number <= spec.n_coordinates and spec.coordinates[number - 1].motion == "rotation":
        return "rad"
    return spec.unit_system.length


def order_column(quantity: str, order: int) -> str:
    return f"{quantity.replace(' ', '')}_order_{order}"


def default_quantity(spec: MechanismSpec) -> str:
    """The quantity a run's spectrum shows by default: ``run.orders``' first, else the force at the valve seat
    (the valve spring's end on it), else at the cam."""
    if spec.run.orders:
        return spec.run.orders[0]
    seat = next((c for c in spec.clearances if spec.seat is not None and c.behind == spec.seat.coordinate), None)
    cam = next(c for c in spec.clearances if c.behind == spec.cam.coordinate)
    return f"F{(seat or cam).ahead}"


def with_orders(spec: MechanismSpec, quantities: tuple[str, ...], field: str = "--orders") -> MechanismSpec:
    """The spec with ``quantities`` added to ``run.orders`` (checked: ``qN``, ``qN-qM`` over the coordinates, cam
    and seat, or ``FN`` with N the coordinate ahead of a clearance)."""
    numbers = set(range(1, spec.n_coordinates + 1)) | {spec.cam.coordinate}
    if spec.seat is not None:
        numbers.add(spec.seat.coordinate)
    forces = {c.ahead for c in spec.clearances}
    from vtool.solvers.model.spring import force_quantity

    springs = [force_quantity(s) for s in spec.springs]  # a data-sheet spring's end force
    for quantity in quantities:
        match = re.fullmatch(r"q(\d+)(?:-q(\d+))?|F(\d+)", quantity.replace(" ", ""))
        ok = match is not None and (int(match[3]) in forces if match[3] else
                                    int(match[1]) in numbers and (match[2] is None or int(match[2]) in numbers))
        if not ok and quantity.replace(" ", "") not in springs:
            raise InputError(field, quantity, f"'q<i>', 'q<i>-q<j>' (i, j in {sorted(numbers)}), 'F<i>' "
                                              f"(i in {sorted(forces)})" + "".join(f" or '{s}'" for s in springs))
    added = tuple(q for q in dict.fromkeys(quantities) if q not in spec.run.orders)
    return dataclasses.replace(spec, run=dataclasses.replace(spec.run, orders=spec.run.orders + added))


@dataclass(frozen=True)
class Spectrum:
    """Order amplitudes of one quantity: ``orders`` (cam orders), ``amplitude`` (the quantity's unit),
    ``phase`` (rad, of the cosine: y = c_0 + Σ A cos(j θ + φ)), over ``cycles`` whole cycles starting at cam
    angle ``start`` (deg), ``rpm`` the cam speed."""

    quantity: str
    unit: str
    orders: np.ndarray
    amplitude: np.ndarray
    phase: np.ndarray
    start: float
    cycles: int
    rpm: float

    @property
    def nyquist(self) -> float:
        return float(self.orders[-1])

    def amplitude_of(self, order: float) -> float:
        """The amplitude at a cam order (0 if it is not a multiple of 1 / cycles)."""
        k = order * self.cycles
        if abs(k - round(k)) > 1e-9 or round(k) >= len(self.amplitude):
            return 0.0
        return float(self.amplitude[round(k)])

    def top(self, count: int = 10, lowest: float = 0.5) -> list[tuple[float, float]]:
        """The ``count`` largest (order, amplitude) above order ``lowest`` (the mean left out), largest first."""
        keep = np.flatnonzero(self.orders >= lowest)
        best = keep[np.argsort(-self.amplitude[keep], kind="stable")[:count]]
        return [(float(self.orders[i]), float(self.amplitude[i])) for i in best]

    def table(self, count: int = 12) -> str:
        """A text table of the mean and the largest orders."""
        lines = [f"{self.quantity} in cam orders over {self.cycles} cycle{'s' if self.cycles > 1 else ''} "
                 f"(cam angle {self.start:g}-{self.start + REVOLUTION * self.cycles:g} deg, {self.rpm:g} rev/min; "
                 f"orders above {self.nyquist:g} fold back)",
                 f"{'order':>8} {'frequency (Hz)':>15} {'amplitude (' + self.unit + ')':>22} {'phase (deg)':>12}",
                 f"{0:>8g} {0:>15g} {self.amplitude[0]:>22.6g} {'(mean)':>12}"]
        for order, amplitude in self.top(count):
            k = int(round(order * self.cycles))
            lines.append(f"{order:>8g} {order * self.rpm / 60.0:>15.6g} {amplitude:>22.6g} "
                         f"{math.degrees(self.phase[k]):>12.2f}")
        return "\n".join(lines)

    def as_dict(self) -> dict:
        return {"quantity": self.quantity, "amplitude_unit": self.unit, "cycles": self.cycles, "start_deg": self.start,
                "rpm": self.rpm, "orders": self.orders.tolist(), "amplitude": self.amplitude.tolist(),
                "phase_rad": self.phase.tolist()}


def whole_cycles(trace: Trace) -> tuple[float, int]:
    """(start in deg, count) of the whole cam cycles in the evaluated window (at least one)."""
    start, end = evaluation_window(trace)
    first = math.ceil(start / REVOLUTION - 1e-9) * REVOLUTION
    count = int(math.floor((end - first) / REVOLUTION + 1e-9))
    if count < 1:
        raise InputError("run.degrees", float(trace.cam_angle[-1]) if len(trace.cam_angle) else 0.0,
                         "a run with a whole cam cycle to analyse (>= 360 deg; >= 720 for a plain run, whose "
                         "first revolution is the start-up)", "deg")
    return first, count


def spectrum(trace: Trace, quantity: str) -> Spectrum:
    """The cam-order spectrum of ``quantity`` over the evaluated whole cycles (see the module doc)."""
    try:
        values = trace.quantity(quantity)
        unit = trace.quantity_unit(quantity)
    except (KeyError, ValueError, IndexError):
        raise InputError("--orders", quantity, "a quantity of this preset: qN (a coordinate), qN-qM, FN (the "
                         "contact force at the clearance ahead of qN) or NAME_force (a data-sheet spring's end "
                         "force)") from None
    start, cycles = whole_cycles(trace)
    return series_spectrum(quantity, unit, trace.cam_angle, values, start, cycles, trace.spec.run.output_interval,
                           trace.spec.run.rpm)


def series_spectrum(quantity: str, unit: str, cam_angle: np.ndarray, values: np.ndarray, start: float, cycles: int,
                    step: float, rpm: float) -> Spectrum:
    """The cam-order spectrum of rows ``values`` at ``cam_angle`` (deg) over ``cycles`` whole cycles from
    ``start``, resampled every ``step`` deg (module doc); any series, e.g. a camshaft's summed torque."""
    per_cycle = max(int(round(REVOLUTION / step)), 4)
    n = per_cycle * cycles
    theta = start + np.arange(n) * (REVOLUTION * cycles / n)
    angle, first = np.unique(cam_angle, return_index=True)  # rows in angle order, one per angle
    y = np.interp(theta, angle, np.asarray(values, dtype=float)[first])
    Y = np.fft.rfft(y)
    amplitude = np.abs(Y) * 2.0 / n
    amplitude[0] = abs(Y[0].real) / n
    if n % 2 == 0:
        amplitude[-1] /= 2.0
    phase = np.angle(Y)
    phase[0] = 0.0 if Y[0].real >= 0 else math.pi
    orders = np.arange(len(Y)) / cycles
    return Spectrum(quantity, unit, orders, amplitude, phase, start, cycles, rpm)


def natural_frequencies(trace: Trace) -> list[tuple[str, float]]:
    """(configuration, natural frequency in Hz) of the configurations the run visited."""
    return natural_frequencies_of(trace.spec, sorted({int(m) for m in np.unique(trace.configuration)}))


def natural_frequencies_of(spec: MechanismSpec, masks: list[int] | None = None) -> list[tuple[str, float]]:
    """(configuration, natural frequency in Hz) of the given configurations (default: the start's), lowest
    first per configuration: the undamped modes of the free coordinates (the cam and a closed seat hold
    theirs); a configuration with no free coordinate has none."""
    from vtool.solvers.model.contact import ContactProblem
    from vtool.solvers.model.damping import undamped_modes
    from vtool.solvers.model.mechanism import assemble

    problem = ContactProblem.for_run(assemble(spec))
    result = []
    for mask in masks if masks is not None else [problem.start_mask]:
        layer = problem.build(mask)
        nf = layer.nf
        if nf == 0:
            continue
        modes = undamped_modes(layer.M[:nf, :nf], layer.K[:nf, :nf])
        for omega in sorted(float(w) for w in modes.omega if w > 0):
            result.append((problem.label(mask), omega / (2 * math.pi)))
    return result


@dataclass(frozen=True)
class Campbell:
    """Order amplitudes of one quantity against cam speed (a sweep's ``<quantity>_order_<k>`` metrics):
    ``amplitude[k - 1, j]`` at order k and speed ``rpm[j]``; ``frequencies`` (configuration, Hz) are the
    natural frequencies drawn as the lines order = f_n 60 / rpm."""

    quantity: str
    unit: str
    rpm: np.ndarray
    amplitude: np.ndarray
    frequencies: list[tuple[str, float]]

    def line(self, hz: float) -> np.ndarray:
        """The cam order of a natural frequency at each speed."""
        return hz * 60.0 / self.rpm


def campbell(rows: list[tuple[float, dict[str, float]]], spec: MechanismSpec, quantity: str) -> Campbell:
    """The Campbell (waterfall) data of ``quantity`` from (rpm, metrics) rows of a sweep whose specs have
    ``quantity`` in ``run.orders``; the natural frequencies of the start configuration and of every
    clearance closed (:func:`natural_frequencies_of`)."""
    if quantity not in spec.run.orders:
        raise InputError("--campbell", quantity, f"a quantity in run.orders ({', '.join(spec.run.orders) or 'none'})")
    rows = sorted(rows, key=lambda r: r[0])
    rpm = np.array([r[0] for r in rows], dtype=float)
    amplitude = np.array([[m.get(order_column(quantity, k), math.nan) for _, m in rows]
                          for k in range(1, spec.run.highest_order + 1)], dtype=float)
    closed = mask_of(spec, tuple(c.name for c in spec.clearances if c.state == ENABLED))
    start = mask_of(spec, spec.initial.closed)
    return Campbell(quantity, quantity_unit(spec, quantity), rpm, amplitude,
                    natural_frequencies_of(spec, sorted({start, closed})))


def dominant_near(spectrum_: Spectrum, frequencies: list[tuple[str, float]], band: float = 0.15,
                  count: int = 3) -> list[tuple[str, float, float, list[tuple[float, float]]]]:
    """For each (configuration, natural frequency in Hz): its cam order ω_n / ω and the ``count`` largest
    orders within ``band`` (a fraction) of it, largest first (empty when none is below the Nyquist order)."""
    cam_hz = spectrum_.rpm / 60.0
    result = []
    for label, hz in frequencies:
        order = hz / cam_hz
        near = np.flatnonzero((spectrum_.orders >= order * (1 - band)) & (spectrum_.orders <= order * (1 + band))
                              & (spectrum_.orders > 0))
        best = near[np.argsort(-spectrum_.amplitude[near], kind="stable")[:count]]
        result.append((label, hz, order, [(float(spectrum_.orders[i]), float(spectrum_.amplitude[i])) for i in best]))
    return result


def dominant_text(spectrum_: Spectrum, frequencies: list[tuple[str, float]], band: float = 0.15) -> str:
    """Lines: for each natural frequency, its cam order and the largest orders within ``band`` of it."""
    lines = [f"dominant orders near each natural frequency (within {100 * band:g} %):"]
    for label, hz, order, best in dominant_near(spectrum_, frequencies, band):
        near = ", ".join(f"order {o:g}: {a:.4g} {spectrum_.unit}" for o, a in best) or "none below the Nyquist order"
        lines.append(f"  {hz:9.1f} Hz ({label}, order {order:.2f}): {near}")
    return "\n".join(lines)

