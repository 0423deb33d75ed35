"""Element stiffness and consistent mass matrices (Gnilka 1971, appendix A).

Element coordinate order follows the thesis (Figs. 2.2 and 2.3):

* bar (axial element, eqs. A.1–A.2): (u_a, u_b), axial displacements of the
  two ends, both positive in the same direction;
* beam (Euler–Bernoulli bending element, eqs. A.3–A.4):
  (w_a, w_b, theta_a, theta_b), end deflections then end rotations.

The signs printed in the thesis' Figs. A.1–A.4 are unreliable in the OCR;
these are the standard matrices, which reproduce the thesis' own printed
system matrices (Fig. 6.8) entry for entry.
"""

from __future__ import annotations

import numpy as np


def bar_matrices(axial_stiffness: float, mass: float) -> tuple[np.ndarray, np.ndarray]:
    """(K_e, M_e) of an axial bar: K_e = EA/L [[1, -1], [-1, 1]], M_e = m/6 [[2, 1], [1, 2]]."""
    k = float(axial_stiffness)
    K = k * np.array([[1.0, -1.0], [-1.0, 1.0]])
    M = float(mass) / 6.0 * np.array([[2.0, 1.0], [1.0, 2.0]])
    return K, M


def beam_matrices(EI: float, L: float, mass: float) -> tuple[np.ndarray, np.ndarray]:
    """(K_e, M_e) of a Hermite beam in the order (w_a, w_b, theta_a, theta_b).

    K_e = EI/L³ [[12, -12, 6L, 6L], [-12, 12, -6L, -6L],
                 [6L, -6L, 4L², 2L²], [6L, -6L, 2L², 4L²]]
    M_e = m/420 [[156, 54, 22L, -13L], [54, 156, 13L, -22L],
                 [22L, 13L, 4L², -3L²], [-13L, -22L, -3L², 4L²]]
    """
    L = float(L)
    K = (float(EI) / L**3) * np.array(
        [
            [12.0, -12.0, 6 * L, 6 * L],
            [-12.0, 12.0, -6 * L, -6 * L],
            [6 * L, -6 * L, 4 * L * L, 2 * L * L],
            [6 * L, -6 * L, 2 * L * L, 4 * L * L],
        ]
    )
    M = (float(mass) / 420.0) * np.array(
        [
            [156.0, 54.0, 22 * L, -13 * L],
            [54.0, 156.0, 13 * L, -22 * L],
            [22 * L, 13 * L, 4 * L * L, -3 * L * L],
            [-13 * L, -22 * L, -3 * L * L, 4 * L * L],
        ]
    )
    return K, M
