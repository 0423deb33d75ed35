"""Modal damping of one contact layer (Gnilka 1971, section III.C).

With the undamped modes of the layer, K φ_i = ω_i² M φ_i, the modal mass
m_i = φ_iᵀ M φ_i, modal stiffness k_i = φ_iᵀ K φ_i and a ratio ζ_i per mode,

    c_i = 2 ζ_i √(k_i m_i)                          (eq. 3.24)
    C   = Φ⁻ᵀ diag(c_i) Φ⁻¹                         (eq. 3.26)

With mass-normalised modes (m_i = 1), Φ⁻¹ = Φᵀ M, so C = M Φ diag(2 ζ_i ω_i) Φᵀ M
without any inverse. Rigid-body modes (ω_i = 0) get no damping, whatever ζ_i.
The result is multiplied by the global damping factor (thesis COFD).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from vtool.errors import RunError

#: A mode whose ω is below this fraction of the largest ω is a rigid-body mode.
RIGID_BODY_TOLERANCE = 1e-7


@dataclass(frozen=True)
class Modes:
    """Undamped modes of (M, K), ascending: omega (rad/s) and mass-normalised columns."""

    omega: np.ndarray
    shapes: np.ndarray


def undamped_modes(M: np.ndarray, K: np.ndarray) -> Modes:
    """Solve K φ = ω² M φ; rigid-body eigenvalues are set to exactly zero.

    A mass matrix that is not positive definite (to working precision) is a
    :class:`vtool.errors.RunError` naming the inputs that make it so.

    Each shape is signed so that its largest-magnitude entry is positive, which
    makes printed shapes reproducible.
    """
    if not (np.all(np.isfinite(M)) and np.all(np.isfinite(K))):
        raise RunError("natural modes: the mass or stiffness matrix has non-finite entries; "
                       "check the members' section, modulus, density and gravity")
    # K φ = ω² M φ reduced with M = L Lᵀ to the standard problem (L⁻¹ K L⁻ᵀ) y = ω² y, φ = L⁻ᵀ y,
    # as LAPACK's sygvd does, with NumPy alone: `vtool solve` imports no scipy.linalg (issue 12)
    try:
        with np.errstate(all="ignore"):
            L = np.linalg.cholesky(M)
            Linv = np.linalg.solve(L, np.eye(M.shape[0]))
            A = Linv @ K @ Linv.T
            A = 0.5 * (A + A.T)
        if not np.all(np.isfinite(A)):
            raise RunError("natural modes: K and M of very different scale overflow the reduced problem "
                           "(M^-1/2 K M^-1/2); check the members' modulus, section, mass and gravity")
        eigenvalues, vectors = np.linalg.eigh(A)
        shapes = Linv.T @ vectors
    except (np.linalg.LinAlgError, ValueError) as exc:
        raise RunError(f"natural modes could not be computed ({str(exc).splitlines()[0][:80]}): the mass "
                       "matrix is not positive definite to working precision; check the members' "
                       "mass, density, specific_weight, section and gravity (masses of very different "
                       "size)") from None
    scale = max(float(np.max(np.abs(eigenvalues))), 1e-300)
    eigenvalues = np.where(np.abs(eigenvalues) < RIGID_BODY_TOLERANCE**2 * scale, 0.0, eigenvalues)
    omega = np.sqrt(np.clip(eigenvalues, 0.0, None))
    for j in range(shapes.shape[1]):
        k = int(np.argmax(np.abs(shapes[:, j])))
        if shapes[k, j] < 0:
            shapes[:, j] *= -1.0
    return Modes(omega, shapes)


def modal_damping(M: np.ndarray, modes: Modes, ratios: np.ndarray, factor: float = 1.0) -> np.ndarray:
    """C = factor · M Φ diag(2 ζ_i ω_i) Φᵀ M for mass-normalised Φ (see module doc)."""
    ratios = np.asarray(ratios, dtype=float)
    MPhi = M @ modes.shapes
    C = MPhi @ np.diag(2.0 * ratios * modes.omega) @ MPhi.T
    return factor * 0.5 * (C + C.T)


def mode_ratios(n_modes: int, default_ratio: float, overrides: tuple[tuple[int, float], ...]) -> np.ndarray:
    """ζ per mode (ascending frequency): the default with 1-based per-mode overrides."""
    ratios = np.full(n_modes, float(default_ratio))
    for mode_number, ratio in overrides:
        if 1 <= mode_number <= n_modes:
            ratios[mode_number - 1] = ratio
    return ratios
