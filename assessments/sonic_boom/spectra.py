"""DAF spectra (DAF against ``tau/T``) and envelopes over families of pulses.

An envelope is the pointwise maximum of the overall DAF over a family of
pulses (the thesis' Figure 3: every type N, P, Q, R, T with ``s`` from 1.6
to 2.2 and ``r1`` from 0 to 0.5). The family is data
(:class:`EnvelopeSpec`); :meth:`EnvelopeSpec.statement` is printed with
every result that uses it, so a reader always knows which envelope produced
a number.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from vtool.assessments.cancel import Cancel, check
from vtool.assessments.sonic_boom.pulses import (
    PULSE_TYPES,
    Pulse,
    PulseParams,
    make_pulse,
    validate,
)
from vtool.assessments.sonic_boom.response import (
    MAX_ENVELOPE_SAMPLES,
    MAX_RATIO,
    QUANTITIES,
    check_cost,
    peak_response,
)
from vtool.errors import InputError

#: Most tau/T values one grid may hold, and most values one envelope range may hold.
MAX_GRID = 200_000
MAX_STEPS = 1000
#: Most pulses one envelope may span.
MAX_MEMBERS = 2000


def _count(low: float, high: float, step: float) -> float:
    """Number of values ``low, low + step, ..., <= high`` as a float (no overflow)."""
    with np.errstate(over="ignore", invalid="ignore"):
        span = (high - low) / step
    return math.floor(span + 1e-9) + 1.0 if math.isfinite(span) else math.inf


def ratio_grid(start: float = 0.0, stop: float = 2.5, step: float = 0.01) -> np.ndarray:
    """``start, start + step, ..., stop`` (inclusive) as ``tau/T`` values."""
    text = f"{start:g}:{stop:g}:{step:g}"
    finite = all(math.isfinite(v) for v in (start, stop, step))
    if not finite or not (step > 0.0) or stop < start or start < 0.0:
        raise InputError("range", text, "finite start:stop:step with 0 <= start <= stop and step > 0")
    if stop > MAX_RATIO:
        raise InputError("range", text, f"stop <= {MAX_RATIO:g} (tau/T)")
    count = _count(start, stop, step)
    if count > MAX_GRID:
        raise InputError("range", text, f"at most {MAX_GRID} points (a larger step)")
    return start + step * np.arange(int(count))


def _steps(low: float, high: float, step: float, field: str = "range") -> tuple[float, ...]:
    count = _count(low, high, step)
    if not count <= MAX_STEPS:
        raise InputError(field, f"[{low:g}, {high:g}, {step:g}]",
                         f"at most {MAX_STEPS} values (a larger step)")
    return tuple(float(round(low + step * k, 12)) for k in range(int(count)))


#: Named envelope families: how type P's rear rise time ``r2`` follows ``r1``.
#: ``thesis``: ``r2 = (s-1) r1`` (same impulse and negative peak as the
#: N-wave, the thesis' observation (ii)); ``equal-rise``: ``r2 = r1``.
FAMILIES: dict[str, str] = {"thesis": "P r2=(s-1)r1", "equal-rise": "P r2=r1"}


@dataclass(frozen=True)
class EnvelopeSpec:
    """A family of idealized pulses whose DAFs are enveloped.

    Every type at every ``s``; ``P`` and ``T`` at every ``r1`` value too
    (``T`` only ``r1 > 0``; ``P`` with ``r1 = 0`` is the N-wave). ``family``
    fixes P's rear rise time (:data:`FAMILIES`: ``thesis`` ``r2 = (s-1) r1``,
    ``equal-rise`` ``r2 = r1``); the other parameters keep their type
    defaults (``Q``, ``R``: ``alpha = 1``; ``T``: ``alpha = 0.5``,
    ``beta = 0.25``, ``r2 = r1``) unless given here.
    """

    types: tuple[str, ...] = PULSE_TYPES
    s_values: tuple[float, ...] = field(default_factory=lambda: _steps(1.6, 2.2, 0.1))
    r1_values: tuple[float, ...] = field(default_factory=lambda: _steps(0.0, 0.5, 0.1))
    alpha: float | None = None
    beta: float | None = None
    family: str = "thesis"

    def members(self) -> list[PulseParams]:
        if self.family not in FAMILIES:
            raise InputError("envelope.family", self.family, f"one of: {', '.join(FAMILIES)}")
        size = len(self.types) * len(self.s_values) * max(len(self.r1_values), 1)
        if size > MAX_MEMBERS:
            raise InputError("envelope", f"{size} pulses", f"at most {MAX_MEMBERS} (coarser s or r1 steps)")
        out: list[PulseParams] = []
        for kind in self.types:
            for s in self.s_values:
                if kind in ("P", "T"):
                    for r1 in self.r1_values:
                        if r1 == 0.0:
                            continue  # P(r1=0) is N; T needs r1 > 0
                        r2 = r1 if kind == "P" and self.family == "equal-rise" else None
                        out.append(PulseParams(kind, s, r1, r2, self.alpha, self.beta))
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
        defaults = ("Q/R alpha=1, T alpha=0.5 beta=0.25 r2=r1"
                    if not extras else ", ".join(extras))
        return (f"envelope ({self.family} family) of types {','.join(self.types)}; "
                f"s {span(self.s_values)}; r1 {span(self.r1_values)}; "
                f"{FAMILIES[self.family]}, {defaults}; {len(self.members())} pulses")


#: the thesis' family (section 1.4): s 1.6-2.2, r1 0-0.5, P r2 = (s-1) r1.
THESIS_ENVELOPE = EnvelopeSpec()
#: the same ranges with P's rear rise equal to its front rise (an option, named).
EQUAL_RISE_ENVELOPE = EnvelopeSpec(family="equal-rise")


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
             damping: float = 0.0, cancel: Cancel | None = None) -> Envelope:
    """Overall-DAF envelope of the family ``spec`` at each ``tau/T`` (``cancel`` polled per member)."""
    if quantity not in QUANTITIES:
        raise InputError("quantity", quantity, f"one of: {', '.join(QUANTITIES)}")
    ratio = np.atleast_1d(np.asarray(ratio, dtype=float))
    pulses: list[Pulse] = [make_pulse(p) for p in spec.members()]
    check_cost(pulses, ratio, MAX_ENVELOPE_SAMPLES)
    curves = np.empty((len(pulses), ratio.size))
    for k, p in enumerate(pulses):
        check(cancel)
        curves[k] = peak_response(p, ratio, damping, quantities=(quantity,)).peaks[quantity].overall
    which = np.argmax(curves, axis=0)
    labels = tuple(pulses[i].label for i in which)
    return Envelope(spec, quantity, float(damping), ratio, curves[which, np.arange(ratio.size)],
                    labels)


def daf_at(source: Pulse | EnvelopeSpec, ratio: np.ndarray | float, quantity: str,
           damping: float = 0.0, cancel: Cancel | None = None) -> tuple[np.ndarray, str]:
    """Overall DAF of a pulse or an envelope at ``tau/T``, with the statement of its source."""
    ratio = np.atleast_1d(np.asarray(ratio, dtype=float))
    check(cancel)
    if isinstance(source, EnvelopeSpec):
        env = envelope(source, ratio, quantity, damping, cancel)
        return env.daf, env.statement
    res = peak_response(source, ratio, damping, quantities=(quantity,))
    damped = "undamped" if damping == 0.0 else f"damping ratio {damping:g}"
    return res.peaks[quantity].overall, f"{quantity} DAF, {damped}, pulse {source.label}"
