"""One reduction primitive and the transformations that feed it.

A reduction is a matrix T (n × k) with u ≈ T q; the reduced system is::

    M_R = Tᵀ M T,   K_R = Tᵀ K T,   F_R = Tᵀ F           (reduce)

Irons' elimination (static or Guyan condensation). Partition the unknowns
into masters m and slaves s::

    [K_mm  K_ms] [u_m]   [F_m]
    [K_sm  K_ss] [u_s] = [F_s]

Slaves take the values of least strain energy for given masters
(∂U/∂u_s = 0, no load on slaves): u_s = −K_ss⁻¹ K_sm u_m, so::

    T_guyan = [I ; −K_ss⁻¹ K_sm]   (rows in m, s order, then permuted back)

Eliminating the slaves one at a time, as the thesis' eqs. (34)–(36) do, is
Gaussian elimination on K and gives exactly this T.

Improved reduced system (IRS, O'Callaghan): adds the slaves' inertia to
first order in the reduced dynamics::

    T_irs = T_guyan + S M T_guyan M_R⁻¹ K_R,   S = [0 0 ; 0 K_ss⁻¹]

Henshell–Ong master selection: eliminate, one at a time, the DOF with the
largest k_ii / m_ii of the current reduced system until ``n_masters`` remain.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg as sla


def _sym(A: np.ndarray) -> np.ndarray:
    return 0.5 * (A + A.T)


def reduce(
    M: np.ndarray, K: np.ndarray, F: np.ndarray, T: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(Tᵀ M T, Tᵀ K T, Tᵀ F), the matrices symmetrized."""
    return _sym(T.T @ M @ T), _sym(T.T @ K @ T), T.T @ F


def _check_masters(n: int, masters: np.ndarray) -> np.ndarray:
    masters = np.asarray(masters, dtype=int)
    if masters.ndim != 1 or masters.size == 0:
        raise ValueError("masters: need at least one master DOF")
    if np.any(masters < 0) or np.any(masters >= n) or np.unique(masters).size != masters.size:
        raise ValueError(f"masters: indices must be distinct and in 0..{n - 1}")
    return masters


def guyan_T(K: np.ndarray, masters: np.ndarray) -> np.ndarray:
    """T_guyan (n × len(masters)); column k belongs to ``masters[k]``."""
    n = K.shape[0]
    m = _check_masters(n, masters)
    s = np.setdiff1d(np.arange(n), m)
    T = np.zeros((n, m.size))
    T[m, np.arange(m.size)] = 1.0
    if s.size:
        K_ss = K[np.ix_(s, s)]
        K_sm = K[np.ix_(s, m)]
        T[s, :] = -sla.solve(K_ss, K_sm, assume_a="pos")
    return T


def irs_T(M: np.ndarray, K: np.ndarray, masters: np.ndarray) -> np.ndarray:
    """T_irs = T_guyan + S M T_guyan M_R⁻¹ K_R (see module docstring)."""
    n = K.shape[0]
    m = _check_masters(n, masters)
    s = np.setdiff1d(np.arange(n), m)
    T = guyan_T(K, m)
    if s.size == 0:
        return T
    M_R = _sym(T.T @ M @ T)
    K_R = _sym(T.T @ K @ T)
    MT = M @ T
    X = sla.solve(M_R, K_R, assume_a="pos")  # M_R⁻¹ K_R
    correction = np.zeros_like(T)
    correction[s, :] = sla.solve(K[np.ix_(s, s)], (MT @ X)[s, :], assume_a="pos")
    return T + correction


def henshell_ong_masters(M: np.ndarray, K: np.ndarray, n_masters: int) -> np.ndarray:
    """Masters left after eliminating, one at a time, the DOF with largest k_ii/m_ii.

    After each elimination the remaining K and M are the Guyan-reduced ones,
    so later choices see the stiffness and inertia the slaves carried.
    Returns the surviving indices, sorted.
    """
    n = K.shape[0]
    if not 1 <= n_masters <= n:
        raise ValueError(f"n_masters: must be in 1..{n}")
    Kc = np.array(K, dtype=float)
    Mc = np.array(M, dtype=float)
    alive = list(range(n))
    while len(alive) > n_masters:
        ratio = np.diag(Kc) / np.diag(Mc)
        s = int(np.argmax(ratio))
        keep = [i for i in range(len(alive)) if i != s]
        k_s = Kc[keep, s] / Kc[s, s]  # T column for the slave: −K_ms/K_ss
        # T = [I; −k_sᵀ] on (keep, s): M_R = M_kk − k M_sk − M_ks kᵀ + M_ss k kᵀ
        Mk = Mc[np.ix_(keep, keep)]
        Ms = Mc[keep, s]
        Mc = Mk - np.outer(k_s, Ms) - np.outer(Ms, k_s) + Mc[s, s] * np.outer(k_s, k_s)
        Kc = Kc[np.ix_(keep, keep)] - np.outer(k_s, Kc[s, keep])
        Kc = _sym(Kc)
        Mc = _sym(Mc)
        del alive[s]
    return np.array(sorted(alive), dtype=int)
