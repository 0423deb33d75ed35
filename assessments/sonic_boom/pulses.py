"""Idealized sonic-boom pulses (thesis 001, Part I, Figure 1(b)) and tabulated pulses.

A pulse is a sequence of :class:`Segment` on a normalized time axis
``t_hat = t / tau`` (``tau`` the positive-phase duration), with the pressure
normalized by the positive peak ``p+``. Inside a segment starting at ``t0``
the pressure is

.. math::

    f(\\hat t) = a + b\\,(\\hat t - t_0) + c\\,\\sin\\kappa(\\hat t - t_0)
                 + d\\,\\cos\\kappa(\\hat t - t_0),

so both the piecewise-linear shapes (N, P, T, any tabulated history) and the
piecewise-sinusoidal ones (Q, R) are exact. A pressure jump (shock) is simply
a change of ``f`` between two segments; the pressure is zero after the last
segment.

The five shapes were reconstructed from the thesis text and its FORTRAN
routine VELDAF (``KOM`` = 1..5 = N, P, Q, R, T); the OCR of Table 1 and
Figure 1 is lost. The evidence for each shape is in ``docs/sonic-boom.md``.

=====  ======================================================================
type   shape (normalized pressure against ``t/tau``)
=====  ======================================================================
N      shock to 1, straight line through 0 at 1 to ``-(s-1)`` at ``s``, shock
       back to 0 (``r1`` = 0).
P      N-wave with finite rise times: linear rise 0 -> 1 over ``r1``, straight
       line through 0 at 1 down to the negative peak at ``s - r2``, linear
       return to 0 over ``r2``. Default ``r2 = (s-1) r1`` (same impulse and
       negative peak as the N-wave, thesis observation (ii)).
Q      half sine ``sin(pi t)`` over ``[0, 1]``, negative half sine of
       amplitude ``alpha`` over ``[1, s]`` (no shocks).
R      shock to 1, quarter cosine to 0 at 1, negative quarter sine to
       ``-alpha`` at ``s``, shock back to 0.
T      shock to 1, fast linear fall to ``alpha (1 - r1)`` at ``r1``, straight
       line of slope ``-alpha`` through 0 at 1 to ``-alpha (s-1)`` at ``s``,
       rear shock up to ``beta``, linear return to 0 over ``r2`` (the pulse
       ends at ``s + r2``, as VELDAF's ``WST1 = WST + WTR2``).
=====  ======================================================================
"""

from __future__ import annotations

import csv
import math
import os
import stat
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from vtool.errors import InputError

#: pulse types in the thesis' order (VELDAF's KOM = 1..5).
PULSE_TYPES: tuple[str, ...] = ("N", "P", "Q", "R", "T")
_NARROWEST = 1e-9  # segments shorter than this (units of tau) are treated as jumps
MAX_PARAMETER = 100.0  # largest s, r2, alpha, |beta|: a pulse 100 tau long is no boom


@dataclass(frozen=True)
class Segment:
    """One piece of a pulse on ``[start, end]`` (units of ``tau``), pressure / ``p+``.

    ``level`` (a) and ``slope`` (b, per unit ``t/tau``) give the linear part;
    ``sin_amp`` (c), ``cos_amp`` (d) and ``freq`` (kappa, rad per unit
    ``t/tau``) the sinusoidal part, all measured from ``start``.
    """

    start: float
    end: float
    level: float = 0.0
    slope: float = 0.0
    sin_amp: float = 0.0
    cos_amp: float = 0.0
    freq: float = 0.0

    @property
    def length(self) -> float:
        return self.end - self.start

    @property
    def sinusoidal(self) -> bool:
        return self.sin_amp != 0.0 or self.cos_amp != 0.0

    def pressure(self, t_hat: np.ndarray) -> np.ndarray:
        """Normalized pressure at ``t_hat`` (no check that ``t_hat`` is inside)."""
        local = np.asarray(t_hat, dtype=float) - self.start
        value = self.level + self.slope * local
        if self.sinusoidal:
            value = value + self.sin_amp * np.sin(self.freq * local)
            value = value + self.cos_amp * np.cos(self.freq * local)
        return value


@dataclass(frozen=True)
class Pulse:
    """A boom pressure history, normalized by ``p+`` and ``tau``.

    ``label`` names the pulse and its parameters (it is printed with every
    result). ``tau_seconds`` and ``peak_pressure`` are set for tabulated
    pulses (the physical scales of the normalization); idealized pulses
    leave them ``None`` and take ``tau`` from the assessment.
    """

    label: str
    segments: tuple[Segment, ...]
    tau_seconds: float | None = None
    peak_pressure: float | None = None

    @property
    def duration(self) -> float:
        """Total duration in units of ``tau``."""
        return self.segments[-1].end

    def pressure(self, t_hat: np.ndarray | float) -> np.ndarray:
        """Normalized pressure at ``t_hat``; right-continuous at jumps, 0 outside."""
        t_hat = np.asarray(t_hat, dtype=float)
        out = np.zeros_like(t_hat)
        for seg in self.segments:
            inside = (t_hat >= seg.start) & (t_hat < seg.end)
            out = np.where(inside, seg.pressure(t_hat), out)
        return out

    def breakpoints(self) -> np.ndarray:
        """Segment boundaries (units of ``tau``), for integrators that must stop there."""
        return np.unique([b for seg in self.segments for b in (seg.start, seg.end)])


# ----------------------------------------------------------------------------
# Parameters and validation


@dataclass(frozen=True)
class PulseParams:
    """Parameters of an idealized pulse; ``None`` means "the type's default".

    ``s``: total / positive duration; ``r1``: rise-time ratio (``t_r / tau``);
    ``r2``: second rise-time ratio (P: rear rise, T: rear-spike width);
    ``alpha``: negative-phase peak ratio (Q, R) or slope ratio (T);
    ``beta``: pressure ratio after T's rear shock.
    """

    kind: str = "N"
    s: float = 2.0
    r1: float = 0.0
    r2: float | None = None
    alpha: float | None = None
    beta: float | None = None

    def resolved(self) -> PulseParams:
        """The same parameters with every type default filled in."""
        kind = self.kind
        r2, alpha, beta = self.r2, self.alpha, self.beta
        if kind == "P" and r2 is None:
            r2 = (self.s - 1.0) * self.r1
        if kind == "T" and r2 is None:
            r2 = self.r1
        if kind in ("Q", "R") and alpha is None:
            alpha = 1.0
        if kind == "T":
            alpha = 0.5 if alpha is None else alpha
            beta = 0.25 if beta is None else beta
        return PulseParams(kind, self.s, self.r1, r2, alpha, beta)

    def label(self) -> str:
        p = self.resolved()
        text = f"{p.kind}(s={p.s:g}"
        if p.kind in ("P", "T"):
            text += f", r1={p.r1:g}, r2={p.r2:g}"
        if p.kind in ("Q", "R", "T"):
            text += f", alpha={p.alpha:g}"
        if p.kind == "T":
            text += f", beta={p.beta:g}"
        return text + ")"


def validate(params: PulseParams, prefix: str = "") -> PulseParams:
    """Check the parameter ranges; raises :class:`InputError` naming the field."""

    def name(key: str) -> str:
        return f"{prefix}{key}"

    if params.kind not in PULSE_TYPES:
        raise InputError(name("type"), params.kind, f"one of: {', '.join(PULSE_TYPES)}")
    p = params.resolved()
    if not (math.isfinite(p.s) and p.s >= 1.0):
        raise InputError(name("s"), p.s, ">= 1 (total / positive duration)")
    for key in ("s", "r2", "alpha", "beta"):
        value = getattr(p, key)
        if value is not None and math.isfinite(value) and abs(value) > MAX_PARAMETER:
            raise InputError(name(key), value, f"|{key}| <= {MAX_PARAMETER:g}")
    if not (math.isfinite(p.r1) and 0.0 <= p.r1 < 1.0):
        raise InputError(name("r1"), p.r1, "in [0, 1) (rise time / positive duration)")
    if p.kind == "N" and p.r1 != 0.0:
        raise InputError(name("r1"), p.r1, "0 for type N (use type P for a rise time)")
    if p.kind == "T" and p.r1 <= 0.0:
        raise InputError(name("r1"), p.r1, "in (0, 1) for type T (the front spike needs a width)")
    if p.kind == "P":
        assert p.r2 is not None
        if not (math.isfinite(p.r2) and 0.0 <= p.r2 <= p.s - 1.0):
            raise InputError(name("r2"), p.r2, f"in [0, s - 1] = [0, {p.s - 1.0:g}]")
    if p.kind == "T":
        assert p.r2 is not None and p.beta is not None
        if not (math.isfinite(p.r2) and p.r2 >= 0.0):
            raise InputError(name("r2"), p.r2, ">= 0")
        if not math.isfinite(p.beta):
            raise InputError(name("beta"), p.beta, "a finite number")
    if p.kind in ("Q", "R", "T"):
        assert p.alpha is not None
        if not (math.isfinite(p.alpha) and p.alpha >= 0.0):
            raise InputError(name("alpha"), p.alpha, ">= 0")
        if p.kind == "T" and p.alpha > 1.0 / (1.0 - p.r1):
            raise InputError(name("alpha"), p.alpha, f"<= 1/(1-r1) = {1.0 / (1.0 - p.r1):g} (peak stays 1)")
    if p.kind in ("Q", "R") and p.s == 1.0 and p.alpha != 0.0:
        pass  # no negative phase: alpha is irrelevant
    return p


def make_pulse(params: PulseParams) -> Pulse:
    """Build the idealized pulse for validated parameters."""
    p = validate(params)
    s, r1 = p.s, p.r1
    segs: list[Segment] = []
    if p.kind == "N" or (p.kind == "P" and r1 == 0.0 and p.r2 == 0.0):
        segs.append(Segment(0.0, s, 1.0, -1.0))
    elif p.kind == "P":
        r2 = float(p.r2)  # type: ignore[arg-type]  # validate() has required this parameter for this pulse kind
        if r1 > 0.0:
            segs.append(Segment(0.0, r1, 0.0, 1.0 / r1))
        fall = -1.0 / (1.0 - r1)
        knee = s - r2
        segs.append(Segment(r1, knee, 1.0, fall))
        if r2 > 0.0:
            low = 1.0 + fall * (knee - r1)
            segs.append(Segment(knee, s, low, -low / r2))
    elif p.kind == "Q":
        segs.append(Segment(0.0, 1.0, sin_amp=1.0, freq=math.pi))
        if s > 1.0:
            segs.append(Segment(1.0, s, sin_amp=-float(p.alpha), freq=math.pi / (s - 1.0)))  # type: ignore[arg-type]  # validate() has required this parameter for this pulse kind
    elif p.kind == "R":
        segs.append(Segment(0.0, 1.0, cos_amp=1.0, freq=math.pi / 2.0))
        if s > 1.0:
            segs.append(
                Segment(1.0, s, sin_amp=-float(p.alpha), freq=math.pi / (2.0 * (s - 1.0)))  # type: ignore[arg-type]  # validate() has required this parameter for this pulse kind
            )
    else:  # T
        alpha, beta, r2 = float(p.alpha), float(p.beta), float(p.r2)  # type: ignore[arg-type]  # validate() has required this parameter for this pulse kind
        segs.append(Segment(0.0, r1, 1.0, -(1.0 - alpha * (1.0 - r1)) / r1))
        segs.append(Segment(r1, s, alpha * (1.0 - r1), -alpha))
        if r2 > 0.0:
            # VELDAF's forced window ends at WST1 = WST + WTR2 whatever beta is:
            # with beta = 0 the pressure is zero there but the motion is still "forced"
            segs.append(Segment(s, s + r2, beta, -beta / r2))
    # A ramp narrower than 1e-9 tau is a jump for any oscillator this tool
    # models; dropping it avoids slopes of 1e14 that no arithmetic survives.
    return Pulse(p.label(), tuple(seg for seg in segs if seg.length > _NARROWEST))


def idealized(kind: str, s: float = 2.0, r1: float = 0.0, r2: float | None = None,
              alpha: float | None = None, beta: float | None = None) -> Pulse:
    """Shorthand: ``idealized("P", s=2, r1=0.2)``."""
    return make_pulse(PulseParams(kind, s, r1, r2, alpha, beta))


# ----------------------------------------------------------------------------
# Tabulated pulses


def tabulated(times: np.ndarray, pressures: np.ndarray, label: str = "tabulated",
              field: str = "pulse") -> Pulse:
    """A piecewise-linear pulse through ``(time [s], pressure)`` points.

    The time origin is the first point; a non-zero first or last pressure is
    a shock. ``tau`` is the positive-phase duration: from the start to the
    first downward zero crossing after the positive peak (the whole duration
    if the pressure never goes back through zero). Pressures are normalized
    by their maximum, which must be positive.
    """
    t = np.asarray(times, dtype=float)
    p = np.asarray(pressures, dtype=float)
    if t.ndim != 1 or t.shape != p.shape or t.size < 2:
        raise InputError(field, f"{t.size} points", "at least 2 (time, pressure) points")
    if not (np.all(np.isfinite(t)) and np.all(np.isfinite(p))):
        raise InputError(field, "non-finite value", "finite times and pressures")
    steps = np.diff(t)
    if np.any(steps <= 0.0):
        bad = int(np.argmax(steps <= 0.0)) + 1
        raise InputError(f"{field} row {bad + 1}", float(t[bad]),
                         f"a time > {t[bad - 1]:g} (strictly increasing)", "s")
    peak_index = int(np.argmax(p))
    peak = float(p[peak_index])
    if peak <= 0.0:
        raise InputError(field, peak, "a positive peak pressure somewhere in the history")
    t = t - t[0]
    tau = float(t[-1])
    for i in range(peak_index, t.size - 1):
        if p[i] > 0.0 >= p[i + 1]:
            tau = float(t[i] + (t[i + 1] - t[i]) * p[i] / (p[i] - p[i + 1]))
            break
    th = t / tau
    f = p / peak
    segs = [
        Segment(float(th[i]), float(th[i + 1]), float(f[i]),
                float((f[i + 1] - f[i]) / (th[i + 1] - th[i])))
        for i in range(t.size - 1)
    ]
    return Pulse(label, tuple(segs), tau_seconds=tau, peak_pressure=peak)


#: Largest pulse CSV read (bytes) and most rows: a recorded boom at 100 kHz
#: for one second is 100 000 rows, about 3 MB.
MAX_CSV_BYTES = 16 * 2**20
MAX_CSV_ROWS = 200_000
_SHOWN = 40  # characters of an offending cell echoed in an error


def shorten(text: object, limit: int = _SHOWN) -> str:
    """``text`` cut to ``limit`` characters (an echoed bad value stays readable)."""
    text = str(text)
    return text if len(text) <= limit else text[: limit - 3] + "..."


def _read_bounded(path: Path) -> str:
    """The file's text: a regular file of at most :data:`MAX_CSV_BYTES`, never a device or pipe."""
    shown = shorten(str(path), 80)
    try:
        info = path.stat()
    except OSError as exc:
        raise InputError("pulse csv", shown, f"an existing file ({exc.strerror})") from None
    if not stat.S_ISREG(info.st_mode):
        raise InputError("pulse csv", shown, "a regular file (not a device, pipe or folder)")
    if info.st_size > MAX_CSV_BYTES:
        raise InputError("pulse csv", f"{shown} ({info.st_size} bytes)",
                         f"at most {MAX_CSV_BYTES} bytes (resample the record)")
    try:
        with path.open("rb") as handle:
            data = handle.read(MAX_CSV_BYTES + 1)
    except OSError as exc:
        raise InputError("pulse csv", shown, f"a readable file ({exc.strerror})") from None
    if len(data) > MAX_CSV_BYTES:
        raise InputError("pulse csv", shown, f"at most {MAX_CSV_BYTES} bytes (resample the record)")
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise InputError("pulse csv", shown,
                         f"UTF-8 text (byte {exc.start} is not): time [s], pressure rows") from None


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def read_pulse_csv(path: str | os.PathLike[str]) -> Pulse:
    """Read a ``time [s], pressure`` CSV (an optional header row) as a tabulated pulse.

    The file must be a regular file of bounded size (:data:`MAX_CSV_BYTES`,
    :data:`MAX_CSV_ROWS`); an error names the file, the row and column and
    what is wrong, never a cell's text (the path may name any file the user can
    read: its content must not appear in a message).
    """
    path = Path(path)
    text = _read_bounded(path)
    lines = text.splitlines()
    if len(lines) > MAX_CSV_ROWS + 1:
        raise InputError(f"{path.name}", f"{len(lines)} rows", f"at most {MAX_CSV_ROWS} rows")
    try:
        rows = [row for row in csv.reader(lines) if row and any(c.strip() for c in row)]
    except csv.Error as exc:
        raise InputError(path.name, "unreadable CSV", f"comma-separated rows ({shorten(exc)})") from None
    times: list[float] = []
    pressures: list[float] = []
    for number, row in enumerate(rows, start=1):
        if len(row) < 2:
            if number == 1:
                continue  # header
            raise InputError(f"{path.name} row {number}", f"{len(row)} column",
                             "two columns: time, pressure")
        try:
            values = [float(cell) for cell in row[:2]]
        except ValueError:
            if number == 1:
                continue  # header
            column = next(i for i, c in enumerate(row[:2]) if not _is_number(c))
            raise InputError(f"{path.name} row {number} column {column + 1}",
                             f"<{len(row[column].strip())} characters that are not a number; not shown>",
                             "a number (time [s], pressure)") from None
        if times and values[0] <= times[-1]:
            raise InputError(f"{path.name} row {number}", "a time not after the previous row's",
                             "strictly increasing times", "s")
        times.append(values[0])
        pressures.append(values[1])
    return tabulated(np.array(times), np.array(pressures), label=f"csv:{path.name}",
                     field=path.name)
