"""Exact (Navier) references for a simply supported rectangular plate.

Mode (m, n): shape W_mn = sin(mπx/a) sin(nπy/b), circular frequency
(thesis eq. 41)::

    ω_mn = π² (m²/a² + n²/b²) √(D / ρh)

modal mass ρh·ab/4. A step load p(x, y) H(t) drives each mode as an undamped
oscillator starting from rest (thesis Appendix B)::

    q_mn(t) = (Q_mn / (ρh ab/4 · ω_mn²)) (1 − cos ω_mn t),   Q_mn = ∫∫ p W_mn dA

    uniform pressure p0:   Q_mn = p0 · 4ab/(π² m n)    (m, n odd, else 0)
    point force P at x1:   Q_mn = P · W_mn(x1, y1)

Displacement, velocity and acceleration at a point are sums over modes of
W_mn(x, y) times q, q̇ = q_s ω sin ωt and q̈ = q_s ω² cos ωt. With a finite
number of modes the sums converge for displacement and velocity; the
acceleration under a point force does not converge (its terms do not
decay), which :func:`step_response` reports rather than hides.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from vtool.assessments.plate.assembly import Plate


@dataclass(frozen=True)
class NavierMode:
    m: int
    n: int
    omega: float  # rad/s


def navier_frequency(plate: Plate, m: int, n: int) -> float:
    """ω_mn in rad/s (thesis eq. 41)."""
    return float(
        np.pi**2 * (m**2 / plate.a**2 + n**2 / plate.b**2)
        * np.sqrt(plate.rigidity / plate.mass_per_area)
    )


def lowest_modes(plate: Plate, count: int) -> list[NavierMode]:
    """The ``count`` lowest Navier modes, sorted by frequency (ties by m, then n)."""
    if count < 1:
        raise ValueError("count: must be >= 1")
    # every mode with m²/a² + n²/b² below that of the count-th mode lies in this box
    limit = int(np.ceil(np.sqrt(count))) + 1
    while True:
        mm, nn = np.meshgrid(np.arange(1, limit + 1), np.arange(1, limit + 1), indexing="ij")
        key = mm.ravel() ** 2 / plate.a**2 + nn.ravel() ** 2 / plate.b**2
        order = np.lexsort((nn.ravel(), mm.ravel(), key))[:count]
        top = key[order[-1]]
        if top <= min(limit**2 / plate.a**2, limit**2 / plate.b**2) or limit > 10 * count:
            break
        limit *= 2
    return [
        NavierMode(int(mm.ravel()[k]), int(nn.ravel()[k]), navier_frequency(plate, mm.ravel()[k], nn.ravel()[k]))
        for k in order
    ]


def _modal_static(plate: Plate, modes: list[NavierMode], load: str, point: tuple[float, float]) -> np.ndarray:
    """Static modal amplitudes q_s,mn per unit load (p0 = 1 or P = 1)."""
    m = np.array([md.m for md in modes], dtype=float)
    n = np.array([md.n for md in modes], dtype=float)
    omega = np.array([md.omega for md in modes])
    modal_mass = plate.mass_per_area * plate.a * plate.b / 4.0
    if load == "uniform":
        odd = (m % 2 == 1) & (n % 2 == 1)
        Q = np.where(odd, 4.0 * plate.a * plate.b / (np.pi**2 * m * n), 0.0)
    elif load == "point":
        x1, y1 = point
        Q = np.sin(m * np.pi * x1 / plate.a) * np.sin(n * np.pi * y1 / plate.b)
    else:
        raise ValueError(f"load: {load!r} is not one of: uniform, point")
    return Q / (modal_mass * omega**2)


def _shapes(plate: Plate, modes: list[NavierMode], x: float, y: float) -> np.ndarray:
    m = np.array([md.m for md in modes], dtype=float)
    n = np.array([md.n for md in modes], dtype=float)
    return np.sin(m * np.pi * x / plate.a) * np.sin(n * np.pi * y / plate.b)


def static_deflection(
    plate: Plate, load: str, n_modes: int = 2000, *, at: tuple[float, float] | None = None,
    point: tuple[float, float] | None = None,
) -> float:
    """Navier series for the static deflection per unit load (p0 = 1 or P = 1)."""
    centre = (plate.a / 2.0, plate.b / 2.0)
    modes = lowest_modes(plate, n_modes)
    qs = _modal_static(plate, modes, load, point or centre)
    return float(_shapes(plate, modes, *(at or centre)) @ qs)


@dataclass(frozen=True)
class ExactResponse:
    """Exact step response at one point by modal superposition.

    ``displacement``, ``velocity`` and ``acceleration`` are per unit load
    (p0 = 1 for the uniform pressure, P = 1 for the point force).
    ``change_*`` is the relative change of each history's peak magnitude when
    the number of modes is halved: the reported convergence.
    ``acceleration_converged`` is True only when the acceleration's peak
    changes by at most :data:`CONVERGED_CHANGE` when the modes are halved: never
    for a point force, whose modal acceleration series diverges, and not for
    the uniform pressure at 200 modes either (its terms decay like 1/(mn),
    and the peak moves 7.6 % from 100 to 200 modes: no exact value to compare
    with).
    """

    t: np.ndarray
    displacement: np.ndarray
    velocity: np.ndarray
    acceleration: np.ndarray
    n_modes: int
    change_displacement: float
    change_velocity: float
    change_acceleration: float
    acceleration_converged: bool


#: The largest relative change of a peak, when the modes are halved, that counts as converged.
CONVERGED_CHANGE = 0.01

_BLOCK = 1_000_000  # (time x mode) entries per block: bounded memory for any grid


def _histories(t: np.ndarray, shapes: np.ndarray, qs: np.ndarray, omega: np.ndarray) -> tuple[np.ndarray, ...]:
    c = shapes * qs
    cv, ca = c * omega, c * omega**2
    disp, vel, acc = (np.empty(t.size) for _ in range(3))
    rows = max(1, _BLOCK // max(omega.size, 1))
    for lo in range(0, t.size, rows):
        wt = np.outer(t[lo:lo + rows], omega)
        cos = np.cos(wt)
        disp[lo:lo + rows] = c.sum() - cos @ c
        vel[lo:lo + rows] = np.sin(wt) @ cv
        acc[lo:lo + rows] = cos @ ca
    return disp, vel, acc


def step_histories(
    plate: Plate, load: str, n_modes: int = 200, *,
    at: tuple[float, float] | None = None, point: tuple[float, float] | None = None,
) -> Callable[[np.ndarray | float], tuple[np.ndarray, ...]]:
    """``t -> (displacement, velocity, acceleration)`` per unit load of :func:`step_response`'s full
    series, its modes computed once: for evaluating the exact response at chosen instants (a peak
    refined between samples)."""
    centre = (plate.a / 2.0, plate.b / 2.0)
    modes = lowest_modes(plate, n_modes)
    omega = np.array([md.omega for md in modes])
    qs = _modal_static(plate, modes, load, point or centre)
    shapes = _shapes(plate, modes, *(at or centre))
    return lambda t: _histories(np.atleast_1d(np.asarray(t, dtype=float)), shapes, qs, omega)


def step_response(
    plate: Plate, load: str, t: np.ndarray, n_modes: int = 200, *,
    at: tuple[float, float] | None = None, point: tuple[float, float] | None = None,
) -> ExactResponse:
    """Centre (or ``at``) response to a step uniform pressure or point force at ``point``."""
    centre = (plate.a / 2.0, plate.b / 2.0)
    t = np.asarray(t, dtype=float)
    modes = lowest_modes(plate, n_modes)
    omega = np.array([md.omega for md in modes])
    qs = _modal_static(plate, modes, load, point or centre)
    shapes = _shapes(plate, modes, *(at or centre))
    full = _histories(t, shapes, qs, omega)
    half = n_modes // 2
    coarse = _histories(t, shapes[:half], qs[:half], omega[:half]) if half else full

    def change(a: np.ndarray, b: np.ndarray) -> float:
        peak = float(np.max(np.abs(a)))
        return abs(peak - float(np.max(np.abs(b)))) / peak if peak > 0 else 0.0

    changes = [change(f, c) for f, c in zip(full, coarse, strict=True)]
    return ExactResponse(
        t, full[0], full[1], full[2], n_modes=n_modes, change_displacement=changes[0],
        change_velocity=changes[1], change_acceleration=changes[2],
        acceleration_converged=(load == "uniform" and changes[2] <= CONVERGED_CHANGE),
    )
