"""Exact response of a single-degree oscillator to a piecewise pulse: no time step.

Non-dimensional form (thesis section 1.3). With ``theta = omega t``, the
displacement in units of the static deflection ``x_s = p+/(m omega^2)`` and
the velocity in units of ``omega x_s = p+/(m omega)``,

.. math::

    x'' + 2\\zeta x' + x = f(\\theta),

where ``f`` is the pressure over ``p+``. The displacement DAF is then
``max|x|`` and the velocity DAF ``max|x'|``; ``u = omega tau = 2 pi tau/T``.

On each segment of the pulse the solution is closed-form. With
``r = -zeta + i omega_d`` (``omega_d = sqrt(1 - zeta^2)``), a segment
``f = a + b theta + Re(F e^{i Omega theta})`` starting from ``(x0, v0)`` gives

.. math::

    x(\\theta) = x_0 + b\\theta + \\mathrm{Re}(C (e^{r\\theta} - 1))
                 + \\mathrm{Re}(F\\,E(\\theta)),

``C`` fixed by the initial state (``Re C = x0 - a + 2 zeta b``,
``Re(r C) = v0 - b``; ``e^{r theta} - 1`` by ``expm1`` so that short, steep
ramps lose nothing to cancellation) and ``E = e[i Omega, r, conj(r)]`` the
second divided difference of ``z -> e^{z theta}`` (the zero-state response to
``e^{i Omega theta}``). ``E`` is evaluated as
``(e[i Omega, r] - e[r, conj(r)]) / (i Omega - conj(r))`` with
``e[i Omega, r] = e^{r theta} theta phi1((i Omega - r) theta)`` and
``phi1(z) = (e^z - 1)/z``, which stays exact through resonance
(``zeta = 0``, ``Omega = 1``) where the textbook ``1/(1 - Omega^2)`` form
divides by zero. Higher derivatives follow from the equation of motion:
``x^(k+2) = f^(k) - 2 zeta x^(k+1) - x^(k)``.

Peaks: the extrema of ``x`` (``v``) inside a segment are the roots of
``v`` (the acceleration). They are bracketed on a grid of at most a tenth
of the fastest period, a possible pair of roots inside one grid cell is
split at the root of the next derivative, and every root is then solved by
safeguarded Newton iteration on the analytic derivative. After the pulse the
motion is free: undamped, its peak is the amplitude ``sqrt(x^2 + v^2)``
(identical for displacement and velocity) at an instant given by ``atan2``;
damped, the first stationary point, also in closed form.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from vtool.assessments.sonic_boom.pulses import Pulse, Segment
from vtool.errors import InputError

QUANTITIES: tuple[str, ...] = ("displacement", "velocity")
_GRID = math.pi / 5.0  # bracketing grid: at most 1/10 of the fastest period
#: Largest tau/T accepted: a pulse 10^4 natural periods long is quasi-static,
#: far beyond any boom (the thesis stops at 2.5).
MAX_RATIO = 1.0e4
#: Cost guard: grid samples (batch x cells, summed over segments) one call may
#: evaluate; about 100 bytes each at peak (a few seconds, < 1 GB).
MAX_SAMPLES = 5_000_000
#: Cost guard of an envelope (its members run one after another).
MAX_ENVELOPE_SAMPLES = 100_000_000


def phi1(z: np.ndarray) -> np.ndarray:
    """``(e^z - 1)/z`` for complex ``z``, exact at and near 0."""
    z = np.asarray(z, dtype=complex)
    zero = z == 0
    zs = np.where(zero, 1.0, z)
    return np.where(zero, 1.0 + 0j, np.expm1(zs) / zs)


def check_damping(damping: float) -> float:
    if not (math.isfinite(damping) and 0.0 <= damping < 1.0):
        raise InputError("damping", damping, "in [0, 1) (damping ratio zeta, underdamped)")
    return float(damping)


class _Piece:
    """Closed-form solution on one segment, for a batch of ``u = omega tau``."""

    def __init__(self, seg: Segment, u: np.ndarray, x0: np.ndarray, v0: np.ndarray,
                 zeta: float) -> None:
        self.zeta = zeta
        self.wd = math.sqrt(1.0 - zeta * zeta)
        self.r = complex(-zeta, self.wd)
        self.L = u * seg.length
        self.a = seg.level
        self.b = seg.slope / u
        self.sinusoidal = seg.sinusoidal
        self.F = complex(seg.cos_amp, -seg.sin_amp)
        self.Om = seg.freq / u
        self.x0 = x0
        self.v0 = v0
        X = x0 - (self.a - 2.0 * zeta * self.b)
        V = v0 - self.b
        self.C = X - 1j * (V + zeta * X) / self.wd

    def state(self, idx: np.ndarray, th: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Displacement and velocity at local ``theta`` for batch members ``idx``."""
        d = self.derivatives(idx, th, 1)
        return d[0], d[1]

    def derivatives(self, idx: np.ndarray, th: np.ndarray, kmax: int) -> list[np.ndarray]:
        """``[x, x', ..., x^(kmax)]`` at local ``theta`` for batch members ``idx``.

        ``x`` and ``x'`` are closed-form; higher derivatives come from the
        equation of motion, ``x^(k+2) = f^(k) - 2 zeta x^(k+1) - x^(k)``.
        """
        r, zeta = self.r, self.zeta
        b = self.b[idx]
        # x = x0 + b theta + Re(C (e^{r theta} - 1)): expm1 keeps short,
        # steep ramps exact (no 1 - cos(theta) cancellation)
        e1 = np.expm1(r * th)
        Ce1 = self.C[idx] * e1
        x = self.x0[idx] + b * th + Ce1.real
        v = self.v0[idx] + (r * Ce1).real
        forcing = [self.a + b * th, b + 0.0 * th] + [0.0 * th] * max(kmax - 3, 0)
        if self.sinusoidal:
            s = 1j * self.Om[idx]
            es = np.exp(s * th)
            e_sr = (e1 + 1.0) * th * phi1((s - r) * th)
            D = np.exp(-zeta * th) * np.sin(self.wd * th) / self.wd
            E = (e_sr - D) / (s - r.conjugate())
            x = x + (self.F * E).real
            v = v + (self.F * (s * E + D)).real
            Fs = self.F * es
            for k in range(min(kmax - 1, len(forcing))):
                forcing[k] = forcing[k] + Fs.real
                Fs = Fs * s
        d = [x, v]
        for k in range(kmax - 1):
            d.append(forcing[k] - 2.0 * zeta * d[k + 1] - d[k])
        return d[: kmax + 1]

    def force(self, idx: np.ndarray, th: np.ndarray) -> np.ndarray:
        """Normalized pressure at local ``theta``."""
        out = self.a + self.b[idx] * th
        if self.sinusoidal:
            out = out + (self.F * np.exp(1j * self.Om[idx] * th)).real
        return out

    def grid_size(self) -> int:
        fastest = np.maximum(1.0, self.Om) if self.sinusoidal else 1.0
        cells = np.ceil(np.max(self.L * fastest) / _GRID) if self.L.size else 1.0
        return int(max(cells, 2.0)) + 1


def _newton(piece: _Piece, order: int, idx: np.ndarray, lo: np.ndarray, hi: np.ndarray,
            g_lo: np.ndarray) -> np.ndarray:
    """Root of ``x^(order)`` in each bracket ``[lo, hi]`` (sign change), Newton + bisection."""
    lo, hi = lo.copy(), hi.copy()
    th = 0.5 * (lo + hi)
    sign_lo = np.sign(g_lo)
    scale = np.maximum(1.0, np.abs(hi))
    active = np.arange(idx.size)
    for _ in range(60):
        if active.size == 0:
            break
        d = piece.derivatives(idx[active], th[active], order + 1)
        g, gp = d[order], d[order + 1]
        same = np.sign(g) == sign_lo[active]
        lo[active] = np.where(same, th[active], lo[active])
        hi[active] = np.where(same, hi[active], th[active])
        with np.errstate(divide="ignore", invalid="ignore"):
            step = np.where(gp != 0.0, g / gp, np.inf)
        new = th[active] - step
        outside = ~((new > lo[active]) & (new < hi[active]))
        new = np.where(outside, 0.5 * (lo[active] + hi[active]), new)
        tol = 1e-13 * scale[active]
        small = np.abs(step) <= tol
        new = np.where(small, np.clip(th[active] - step, lo[active], hi[active]), new)
        done = small | (np.abs(new - th[active]) <= tol) | (hi[active] - lo[active] <= tol)
        th[active] = new
        active = active[~done]
    return th


@dataclass
class _Best:
    value: np.ndarray
    theta: np.ndarray

    def offer(self, idx: np.ndarray, values: np.ndarray, theta: np.ndarray) -> None:
        """Keep, per batch member, the largest |value| offered and where it was."""
        mag = np.abs(values)
        order = np.argsort(mag, kind="stable")
        idx, mag, theta = idx[order], mag[order], theta[order]
        # last occurrence of each idx holds its largest magnitude
        last = np.unique(idx[::-1], return_index=True)[1]
        last = idx.size - 1 - last
        sel_idx, sel_mag, sel_th = idx[last], mag[last], theta[last]
        better = sel_mag > self.value[sel_idx]
        self.value[sel_idx[better]] = sel_mag[better]
        self.theta[sel_idx[better]] = sel_th[better]

    def offer_rows(self, values: np.ndarray, theta: np.ndarray) -> None:
        """Offer a (batch, k) array: one row per batch member."""
        j = np.argmax(np.abs(values), axis=1)
        rows = np.arange(values.shape[0])
        mag = np.abs(values[rows, j])
        better = mag > self.value
        self.value[better] = mag[better]
        self.theta[better] = theta[rows, j][better]


def _closed_form_roots(piece: _Piece, order: int) -> tuple[np.ndarray, np.ndarray] | None:
    """Stationary points of ``x^(order)`` on a linear segment, where they are closed-form.

    On a linear segment ``x' = b + Re(r C e^{r theta})`` and
    ``x'' = Re(r^2 C e^{r theta})``. The roots of ``x''`` are
    ``omega_d theta = pi/2 - arg(r^2 C) + k pi``; undamped, the roots of ``x'``
    solve ``|C| sin(theta + arg C) = b``. Returns ``(batch index, theta)``
    of the roots inside ``[0, L]``, or ``None`` when there is no closed form
    (a sinusoidal segment, or displacement with damping).
    """
    if piece.sinusoidal or (order == 0 and piece.zeta != 0.0):
        return None
    n = piece.L.size
    r, wd = piece.r, piece.wd
    if order == 1:
        first = np.mod(math.pi / 2.0 - np.angle(r * r * piece.C), math.pi) / wd
        starts, period = [first], math.pi / wd
    else:
        mag = np.abs(piece.C)
        with np.errstate(divide="ignore", invalid="ignore"):
            ratio = np.where(mag > 0.0, piece.b / mag, np.inf)
        ok = np.abs(ratio) <= 1.0
        base = np.arcsin(np.clip(ratio, -1.0, 1.0))
        phase = np.angle(piece.C)
        starts = [np.where(ok, np.mod(base - phase, 2.0 * math.pi), np.inf),
                  np.where(ok, np.mod(math.pi - base - phase, 2.0 * math.pi), np.inf)]
        period = 2.0 * math.pi
    count = int(np.ceil(np.max(piece.L) / period)) + 1 if n else 0
    k = np.arange(count) * period
    th = np.concatenate([s[:, None] + k[None, :] for s in starts], axis=1)
    bi, bj = np.nonzero(th <= piece.L[:, None])
    return bi, th[bi, bj]


def _piece_extrema(piece: _Piece, order: int, offset: np.ndarray, best: _Best) -> None:
    """Offer every extremum of ``x^(order)`` on the segment (plus grid values) to ``best``."""
    n = piece.L.size
    closed = _closed_form_roots(piece, order)
    if closed is not None:
        ends = np.concatenate([np.zeros(n), piece.L])
        bi = np.concatenate([np.arange(n), np.arange(n), closed[0]])
        th = np.concatenate([ends, closed[1]])
        values = piece.derivatives(bi, th, order)[order]
        best.offer(bi, values, th + offset[bi])
        return
    m = piece.grid_size()
    xi = np.linspace(0.0, 1.0, m)
    th = piece.L[:, None] * xi[None, :]
    idx = np.broadcast_to(np.arange(n)[:, None], th.shape)
    d = piece.derivatives(idx, th, order + 3)
    q, g, gp = d[order], d[order + 1], d[order + 2]
    best.offer_rows(q, th + offset[:, None])

    crossing = g[:, :-1] * g[:, 1:] < 0.0
    bi, bj = np.nonzero(crossing)
    lo, hi, glo = th[bi, bj], th[bi, bj + 1], g[bi, bj]

    # A pair of roots of g inside one cell: g has an extremum there (gp changes
    # sign). If |g''| <= M on the cell, g moves by at most M h^2 / 2 between a
    # cell end and that extremum, so cells where |g| stays above that at both
    # ends cannot hold a pair. M is the grid maximum of |g''| on the row with a
    # 1.5 margin (the grid resolves 1/10 of the fastest period).
    h = (piece.L / (m - 1))[:, None]
    reach = 0.75 * np.max(np.abs(d[order + 3]), axis=1, keepdims=True) * h * h
    near = np.minimum(np.abs(g[:, :-1]), np.abs(g[:, 1:])) <= reach
    pair = (~crossing) & near & (gp[:, :-1] * gp[:, 1:] < 0.0) & (g[:, :-1] != 0.0)
    pi, pj = np.nonzero(pair)
    if pi.size:
        mid = _newton(piece, order + 2, pi, th[pi, pj], th[pi, pj + 1], gp[pi, pj])
        g_mid = piece.derivatives(pi, mid, order + 1)[order + 1]
        split = np.sign(g_mid) != np.sign(g[pi, pj])
        pi, pj, mid = pi[split], pj[split], mid[split]
        bi = np.concatenate([bi, pi, pi])
        lo = np.concatenate([lo, th[pi, pj], mid])
        hi = np.concatenate([hi, mid, th[pi, pj + 1]])
        glo = np.concatenate([glo, g[pi, pj], g_mid[split]])
    if bi.size:
        roots = _newton(piece, order + 1, bi, lo, hi, glo)
        values = piece.derivatives(bi, roots, order)[order]
        best.offer(bi, values, roots + offset[bi])


def _free_peak(x: np.ndarray, v: np.ndarray, zeta: float, order: int) -> tuple[np.ndarray, np.ndarray]:
    """Peak of |x^(order)| for t >= end of pulse, and its local theta."""
    if zeta == 0.0:
        amp = np.hypot(x, v)
        phase = np.arctan2(v, x) if order == 0 else np.arctan2(-x, v)
        return amp, np.mod(phase, math.pi)
    wd = math.sqrt(1.0 - zeta * zeta)
    r = complex(-zeta, wd)
    C = x - 1j * (v + zeta * x) / wd
    coef = C * r**order  # x^(order) = Re(coef e^{r theta})
    th1 = np.mod(math.pi / 2.0 - np.angle(coef * r), math.pi) / wd
    at1 = np.abs((coef * np.exp(r * th1)).real)
    at0 = np.abs(coef.real)
    first = at1 >= at0
    return np.where(first, at1, at0), np.where(first, th1, 0.0)


@dataclass(frozen=True)
class Peaks:
    """Peak non-dimensional response (DAF) and its instant (``t/tau``) per ``tau/T``.

    ``forced``: while the pulse acts; ``free``: after it ends; ``overall``:
    the larger of the two.
    """

    forced: np.ndarray
    forced_at: np.ndarray
    free: np.ndarray
    free_at: np.ndarray

    @property
    def overall(self) -> np.ndarray:
        return np.maximum(self.forced, self.free)

    @property
    def overall_at(self) -> np.ndarray:
        return np.where(self.free >= self.forced, self.free_at, self.forced_at)


@dataclass(frozen=True)
class PeakResponse:
    """DAFs of one pulse against ``tau/T`` (``ratio``), for each requested quantity."""

    pulse: str
    ratio: np.ndarray
    damping: float
    peaks: dict[str, Peaks]

    @property
    def velocity(self) -> Peaks:
        return self.peaks["velocity"]

    @property
    def displacement(self) -> Peaks:
        return self.peaks["displacement"]


def _ratios(ratio: np.ndarray | float) -> np.ndarray:
    ratio = np.atleast_1d(np.asarray(ratio, dtype=float))
    if ratio.ndim != 1 or not np.all(np.isfinite(ratio)) or np.any(ratio < 0.0):
        bad = ratio[~(np.isfinite(ratio) & (ratio >= 0.0))]
        raise InputError("tau/T", float(bad[0]) if bad.size else "not a list", ">= 0")
    if ratio.size and float(np.max(ratio)) > MAX_RATIO:
        raise InputError("tau/T", float(np.max(ratio)),
                         f"<= {MAX_RATIO:g} (positive duration x natural frequency; check the "
                         "durations, frequencies and structure properties)")
    return ratio


def samples_estimate(pulse: Pulse, ratio: np.ndarray | float) -> int:
    """Grid samples :func:`peak_response` evaluates per quantity (the cost guard's measure).

    Each segment is gridded at a tenth of the fastest period over the whole
    batch: ``n_ratios x (ceil(max(2 pi r_max L, kappa L) / (pi/5)) + 1)``.
    """
    ratio = np.atleast_1d(np.asarray(ratio, dtype=float))
    if ratio.size == 0:
        return 0
    top = 2.0 * math.pi * float(np.max(ratio))
    cells = 0.0
    for seg in pulse.segments:
        span = max(top * seg.length, seg.length * seg.freq, 2.0 * _GRID) / _GRID
        if not span < 1e18:  # inf or absurd: the guard refuses it
            return 2**62
        cells += math.ceil(span) + 1
    return int(min(cells * ratio.size, 2**62))


def check_cost(pulses: list[Pulse], ratio: np.ndarray | float, limit: int = MAX_SAMPLES) -> int:
    """Refuse (InputError) responses whose grids exceed ``limit`` samples; returns the estimate."""
    estimate = sum(samples_estimate(p, ratio) for p in pulses)
    if estimate > limit:
        size = np.atleast_1d(np.asarray(ratio)).size
        raise InputError("tau/T grid", f"{size} values x {len(pulses)} pulse(s) = {estimate:.3g} samples",
                         f"<= {limit:.0e} samples (use fewer tau/T values, a coarser step, "
                         "fewer envelope members or shorter pulses)")
    return estimate


def end_state(pulse: Pulse, ratio: np.ndarray | float, damping: float = 0.0
              ) -> tuple[np.ndarray, np.ndarray]:
    """Non-dimensional displacement and velocity at the end of the pulse."""
    zeta = check_damping(damping)
    ratio = _ratios(ratio)
    u = 2.0 * math.pi * np.where(ratio > 0.0, ratio, 1.0)
    x = np.zeros_like(u)
    v = np.zeros_like(u)
    idx = np.arange(u.size)
    for seg in pulse.segments:
        piece = _Piece(seg, u, x, v, zeta)
        x, v = piece.state(idx, piece.L)
    zero = ratio == 0.0
    return np.where(zero, 0.0, x), np.where(zero, 0.0, v)


def peak_response(pulse: Pulse, ratio: np.ndarray | float, damping: float = 0.0,
                  quantities: tuple[str, ...] = QUANTITIES) -> PeakResponse:
    """Forced, free and overall DAFs of ``pulse`` for each ``tau/T`` in ``ratio``.

    ``ratio = 0`` (a pulse of no duration) gives zero response.
    """
    zeta = check_damping(damping)
    ratio = _ratios(ratio)
    for q in quantities:
        if q not in QUANTITIES:
            raise InputError("quantity", q, f"one of: {', '.join(QUANTITIES)}")
    check_cost([pulse], ratio)
    live = np.nonzero(ratio > 0.0)[0]
    u = 2.0 * math.pi * ratio[live]
    n = u.size
    forced = {q: _Best(np.zeros(n), np.zeros(n)) for q in quantities}
    x = np.zeros(n)
    v = np.zeros(n)
    idx = np.arange(n)
    for seg in pulse.segments:
        piece = _Piece(seg, u, x, v, zeta)
        offset = u * seg.start
        for q in quantities:
            _piece_extrema(piece, QUANTITIES.index(q), offset, forced[q])
        x, v = piece.state(idx, piece.L)
    end = u * pulse.duration
    peaks: dict[str, Peaks] = {}
    for q in quantities:
        free, th = _free_peak(x, v, zeta, QUANTITIES.index(q))
        full = [np.zeros(ratio.size) for _ in range(4)]
        full[0][live] = forced[q].value
        full[1][live] = forced[q].theta / u
        full[2][live] = free
        full[3][live] = (end + th) / u
        peaks[q] = Peaks(*full)
    return PeakResponse(pulse.label, ratio, zeta, peaks)


def history(pulse: Pulse, ratio: float, t_hat: np.ndarray, damping: float = 0.0
            ) -> tuple[np.ndarray, np.ndarray]:
    """Exact non-dimensional displacement and velocity at instants ``t_hat = t/tau``."""
    zeta = check_damping(damping)
    ratio_arr = _ratios(ratio)
    if ratio_arr.size != 1 or ratio_arr[0] <= 0.0:
        raise InputError("tau/T", ratio, "> 0 (one value)")
    u = np.array([2.0 * math.pi * ratio_arr[0]])
    t_hat = np.asarray(t_hat, dtype=float)
    xs = np.zeros_like(t_hat)
    vs = np.zeros_like(t_hat)
    x = np.zeros(1)
    v = np.zeros(1)
    one = np.zeros(1, dtype=int)
    for seg in pulse.segments:
        piece = _Piece(seg, u, x, v, zeta)
        inside = (t_hat >= seg.start) & (t_hat < seg.end)
        if np.any(inside):
            th = u[0] * (t_hat[inside] - seg.start)
            xi, vi = piece.state(np.zeros(th.shape, dtype=int), th)
            xs[inside], vs[inside] = xi, vi
        x, v = piece.state(one, piece.L)
    after = t_hat >= pulse.duration
    if np.any(after):
        th = u[0] * (t_hat[after] - pulse.duration)
        wd = math.sqrt(1.0 - zeta * zeta)
        r = complex(-zeta, wd)
        C = x[0] - 1j * (v[0] + zeta * x[0]) / wd
        e = C * np.exp(r * th)
        xs[after], vs[after] = e.real, (r * e).real
    return xs, vs
