"""Prescribed motions (cam, seat) as truncated Fourier series: one form for every back end.

Each source s moves as

    x_s(t) = c_s + Σ_{k=1..K} ( a_sk cos kωt + b_sk sin kωt )
    v_s(t) = Σ_k kω ( -a_sk sin kωt + b_sk cos kωt )
    a_s(t) = -Σ_k (kω)² ( a_sk cos kωt + b_sk sin kωt )

with ω the cam speed in rad/s and t = 0 at the preset's cam angle zero (the
thesis' mid-stroke). The thesis' harmonic cam q9 = A sin ωt + XZERO is
c = XZERO, b_1 = A; a fixed seat is c = position with no harmonics. A cam
given by a lift table is fitted by such a series (:mod:`vtool.solvers.model.cam`),
so velocity, acceleration and jerk are smooth, the Newmark kernel evaluates it
directly, and the exact back end sums one particular solution per harmonic.

:func:`evaluate` is the plain NumPy reference of the kernel's source
evaluation.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class SourceSeries:
    """Fourier coefficients of every prescribed source (see module doc).

    ``numbers`` are the sources' coordinate numbers (cam first, then the
    seat); ``const`` has shape (ns,), ``cos`` and ``sin`` (ns, K): column
    k - 1 holds harmonic k.
    """

    omega: float
    numbers: tuple[int, ...]
    const: np.ndarray
    cos: np.ndarray
    sin: np.ndarray

    @property
    def n_sources(self) -> int:
        return len(self.numbers)

    @property
    def n_harmonics(self) -> int:
        return int(self.cos.shape[1])

    def index(self, number: int) -> int:
        return self.numbers.index(number)


def evaluate(series: SourceSeries, s: int, t: float | np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(x, v, a) of source s at t (scalars or arrays of t)."""
    t = np.asarray(t, dtype=float)
    x = np.full(t.shape, series.const[s])
    v = np.zeros(t.shape)
    a = np.zeros(t.shape)
    for k in range(series.n_harmonics):
        wk = (k + 1) * series.omega
        ck, sk = series.cos[s, k], series.sin[s, k]
        if ck == 0.0 and sk == 0.0:
            continue
        c, sn = np.cos(wk * t), np.sin(wk * t)
        x = x + ck * c + sk * sn
        v = v + wk * (-ck * sn + sk * c)
        a = a - wk * wk * (ck * c + sk * sn)
    return x, v, a
