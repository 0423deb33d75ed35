"""DAF spectra (DAF against ``tau/T``) and envelopes over families of pulses.

An envelope is the pointwise maximum of the overall DAF over a family of
pulses (the thesis' Figure 3: every type N, P, Q, R, T with ``s`` from 1.6
to 2.2 and ``r1`` from 0 to 0.5). The family is data
(:class:`EnvelopeSpec`); :meth:`EnvelopeSpec.statement` is printed with
every result that uses it, so a reader always knows which envelope produced
a number.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from vtool.assessments.sonic_boom.pulses import (
    PULSE_TYPES,
    Pulse,
    PulseParams,
    make_pulse,
    validate,
)
from vtool.assessments.sonic_boom.response import QUANTITIES, peak_response
from vtool.errors import InputError


def ratio_grid(start: float = 0.0, stop: float = 2.5, step: float = 0.01) -> np.ndarray:
    """``start, start + step, ..., stop`` (inclusive) as ``tau/T`` values."""
    if not (step > 0.0) or stop < start or start < 0.0:
        raise InputError("range", f"{start:g}:{stop:g}:{step:g}",
                         "start:stop:step with 0 <= start <= stop and step > 0")
    count = int(np.floor((stop - start) / step + 1e-9)) + 1
    if count > 200_000:
        raise InputError("range", f"{start:g}:{stop:g}:{step:g}", "at most 200000 points")
    return start + step * np.arange(count)


def _steps(low: float, high: float, step: float) -> tuple[float, ...]:
    count = int(np.floor((high - low) / step + 1e-9)) + 1
    return tuple(float(round(low + step * k, 12)) for k in range(count))


@dataclass(frozen=True)
class EnvelopeSpec:
    """A family of idealized pulses whose DAFs are enveloped.

    ``P`` and ``T`` take every ``r1`` value (``T`` only ``r1 > 0``; ``P`` with
    ``r1 = 0`` is the N-wave); the other parameters keep their type defaults
    (``P``: ``r2 = (s-1) r1``; ``Q``, ``R``: ``alpha = 1``; ``T``:
    ``alpha = 0.5``, ``beta = 0.25``, ``r2 = r1``) unless given here.
    """

    types: tuple[str, ...] = PULSE_TYPES
    s_values: tuple[float, ...] = field(default_factory=lambda: _steps(1.6, 2.2, 0.1))
    r1_values: tuple[float, ...] = field(default_factory=lambda: _steps(0.0, 0.5, 0.1))
    alpha: float | None = None
    beta: float | None = None

    def members(self) -> list[PulseParams]:
        out: list[PulseParams] = []
        for kind in self.types:
            for s in self.s_values:
                if kind in ("P", "T"):
                    for r1 in self.r1_values:
                        if r1 == 0.0:
                            continue  # P(r1=0) is N; T needs r1 > 0
                        out.append(PulseParams(kind, s, r1, None, self.alpha, self.beta))
                elif kind == "N":
                    out.append(PulseParams(kind, s, 0.0))
                else:
                    out.append(PulseParams(kind, s, 0.0, None, self.alpha, self.beta))
        if not out:
            raise InputError("envelope", "empty family", "at least one pulse (types, s, r1)")
        for params in out:
            validate(params, prefix="envelope.")
        return out

    def statement(self) -> str:
        def span(values: tuple[float, ...]) -> str:
            if len(values) == 1:
                return f"{values[0]:g}"
            step = values[1] - values[0]
            return f"{values[0]:g}-{values[-1]:g} step {step:g}"

        extras = []
        if self.alpha is not None:
            extras.append(f"alpha={self.alpha:g}")
        if self.beta is not None:
            extras.append(f"beta={self.beta:g}")
        defaults = ("P r2=(s-1)r1, Q/R alpha=1, T alpha=0.5 beta=0.25 r2=r1"
                    if not extras else ", ".join(extras))
        return (f"envelope of types {','.join(self.types)}; s {span(self.s_values)}; "
                f"r1 {span(self.r1_values)}; {defaults}; {len(self.members())} pulses")


#: the thesis' family (section 1.4): s 1.6-2.2, r1 0-0.5.
THESIS_ENVELOPE = EnvelopeSpec()


@dataclass(frozen=True)
class Envelope:
    """Pointwise maximum overall DAF over a family, and which pulse gives it."""

    spec: EnvelopeSpec
    quantity: str
    damping: float
    ratio: np.ndarray
    daf: np.ndarray
    governing: tuple[str, ...]  # label of the pulse giving the maximum, per ratio

    @property
    def statement(self) -> str:
        damping = "undamped" if self.damping == 0.0 else f"damping ratio {self.damping:g}"
        return f"{self.quantity} DAF, {damping}, {self.spec.statement()}"


def envelope(spec: EnvelopeSpec, ratio: np.ndarray | float, quantity: str = "velocity",
             damping: float = 0.0) -> Envelope:
    """Overall-DAF envelope of the family ``spec`` at each ``tau/T``."""
    if quantity not in QUANTITIES:
        raise InputError("quantity", quantity, f"one of: {', '.join(QUANTITIES)}")
    ratio = np.atleast_1d(np.asarray(ratio, dtype=float))
    pulses: list[Pulse] = [make_pulse(p) for p in spec.members()]
    curves = np.array([
        peak_response(p, ratio, damping, quantities=(quantity,)).peaks[quantity].overall
        for p in pulses
    ])
    which = np.argmax(curves, axis=0)
    labels = tuple(pulses[i].label for i in which)
    return Envelope(spec, quantity, float(damping), ratio, curves[which, np.arange(ratio.size)],
                    labels)


def daf_at(source: Pulse | EnvelopeSpec, ratio: np.ndarray | float, quantity: str,
           damping: float = 0.0) -> tuple[np.ndarray, str]:
    """Overall DAF of a pulse or an envelope at ``tau/T``, with the statement of its source."""
    ratio = np.atleast_1d(np.asarray(ratio, dtype=float))
    if isinstance(source, EnvelopeSpec):
        env = envelope(source, ratio, quantity, damping)
        return env.daf, env.statement
    res = peak_response(source, ratio, damping, quantities=(quantity,))
    damped = "undamped" if damping == 0.0 else f"damping ratio {damping:g}"
    return res.peaks[quantity].overall, f"{quantity} DAF, {damped}, pulse {source.label}"
