"""Free vibration of a reduced model against the exact Navier frequencies.

Percentage error (thesis eq. 40)::

    error = (ω_approx − ω_exact) / ω_exact × 100 %

matched in ascending order: the k-th lowest computed frequency against the
k-th lowest exact one. The largest computed frequency is reported as the
ratio ω_max / ω_11 (ω_11 exact; thesis eq. 42): it sets the RK4 step.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla

from vtool.assessments.plate.assembly import Plate
from vtool.assessments.plate.exact import NavierMode, lowest_modes
from vtool.assessments.plate.model import ReducedModel
from vtool.threads import limited


@dataclass(frozen=True)
class FreeVibration:
    """Frequencies of one reduced model and their errors against exact ones."""

    case: str
    size: int
    omega: np.ndarray  # rad/s, all KS of them, ascending
    exact: list[NavierMode]  # the lowest min(count, KS) exact modes
    errors_pct: np.ndarray  # against ``exact``, same length
    omega_max_ratio: float  # ω_max / ω_11 (exact)
    solve_seconds: float  # eigenproblem only

    @property
    def fundamental_error_pct(self) -> float:
        return float(self.errors_pct[0])


def natural_frequencies(M: np.ndarray, K: np.ndarray) -> np.ndarray:
    """Ascending circular frequencies of K φ = ω² M φ (rad/s)."""
    lam = sla.eigh(K, M, eigvals_only=True)
    return np.sqrt(np.clip(lam, 0.0, None))


@limited()  # small dense matrices: one BLAS thread (vtool.threads)
def free_vibration(plate: Plate, model: ReducedModel, count: int = 6) -> FreeVibration:
    """Lowest ``count`` frequencies of a reduced model with their percentage errors."""
    start = time.perf_counter()
    omega = natural_frequencies(model.M, model.K)
    seconds = time.perf_counter() - start
    k = min(count, omega.size)
    exact = lowest_modes(plate, k)
    ref = np.array([md.omega for md in exact])
    errors = (omega[:k] - ref) / ref * 100.0
    omega_11 = lowest_modes(plate, 1)[0].omega
    return FreeVibration(
        case=model.case.name, size=model.size, omega=omega, exact=exact,
        errors_pct=errors, omega_max_ratio=float(omega[-1] / omega_11), solve_seconds=seconds,
    )


def convergence_order(h: np.ndarray, errors: np.ndarray) -> float:
    """Slope of log|error| against log h (least squares): the observed order."""
    h = np.asarray(h, dtype=float)
    e = np.abs(np.asarray(errors, dtype=float))
    slope, _ = np.polyfit(np.log(h), np.log(e), 1)
    return float(slope)
