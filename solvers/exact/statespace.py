"""A configuration between events as a linear system with Fourier forcing, and its exact solution.

In configuration c, with F the free layer coordinates, P the prescribed ones
(moved by the sources) and y = (x_F, v_F),

    y' = A y + b(t),   A = ⎡ 0            I          ⎤,
                           ⎣ -M_FF⁻¹K_FF  -M_FF⁻¹C_FF ⎦

    b(t) = ⎡ 0                                           ⎤
           ⎣ -M_FF⁻¹ (M_FP a_P + C_FP v_P + K_FP x_P)(t) ⎦

The sources are Fourier series (:class:`vtool.solvers.model.sources.SourceSeries`),
x_P(t) = c + Σ_k a_k cos kωt + b_k sin kωt, so every forced quantity is a
combination of the basis

    u(t) = (1, cos ωt, …, cos Kωt, sin ωt, …, sin Kωt)     (2K + 1 functions)

b(t) = B u(t), and the particular solution is y_p(t) = Y u(t), one term per
harmonic, each from one direct solve (no least squares):

    constant:  K_FF X₀ = -K_FP c,  Y₀ = (X₀, 0);
    harmonic k, complex amplitude X_P = a_k - i b_k of the sources:
        (K_FF - (kω)² M_FF + ikω C_FF) X_k = -(K_FP - (kω)² M_FP + ikω C_FP) X_P,
        Yc_k = Re (X_k, ikω X_k),  Ys_k = -Im (X_k, ikω X_k).

The constant solve works in the mechanism's own stiffness, not in A (whose
condition number reaches 1e12 from the mixed units of x and v). A stiffness
with a null space (a free rigid-body motion) is solved on its range by the
SVD; a constant load with a component on the null space has no steady
solution and is an error naming the configuration. A harmonic that hits an
undamped natural frequency is an error too.

The homogeneous part is propagated exactly by :class:`Propagator`: by the
eigendecomposition A = V Λ V⁻¹ (e^{Aτ} = V e^{Λτ} V⁻¹, so a state at any τ is
2n exponentials and one matrix-vector product, and a monitor g·y(τ) is a sum
of exponentials), or, when V is ill-conditioned (defective A, e.g. a free
undamped rigid body), by scipy's expm of A times the step, computed once per
step size and reused.

:func:`state_space` takes plain arrays; :func:`from_layer` reads one
configuration's ordered layer and the sources from the contact problem
(:mod:`vtool.solvers.model.contact`).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
import scipy.linalg

from vtool.errors import RunError
from vtool.solvers.model.sources import SourceSeries

#: eigenvector matrices with a larger condition number are not used (expm instead):
#: the modal propagation loses about cond(V) * eps relative
MODAL_CONDITION_LIMIT = 1e4


@dataclass
class StateSpace:
    """y' = A y + B u(t) of one configuration, its particular solution Y u(t), and output maps.

    Coefficient matrices (B, Y, Q, H) have one column per basis function u(t)
    (see module doc).
    """

    mask: int
    free: np.ndarray  # layer columns that are free
    A: np.ndarray  # (2nf, 2nf)
    B: np.ndarray  # (2nf, 2K+1): forcing b(t) = B u(t)
    Y: np.ndarray  # (2nf, 2K+1): particular solution y_p(t) = Y u(t)
    omega: float
    omega_max: float  # largest |eigenvalue| of A
    T: np.ndarray | None = None  # (2nf, 2nf) balancing: z = T y in modal energy coordinates
    Tinv: np.ndarray | None = None
    # affine maps, filled by PiecewiseRun.space: z = P y + Q u(t), monitors = G y + H u(t)
    P: np.ndarray | None = None  # (3n, 2nf): full (x, v, a) from y
    Q: np.ndarray | None = None  # (3n, 2K+1)
    G: np.ndarray | None = None  # (ncl, 2nf): monitors from y
    H: np.ndarray | None = None  # (ncl, 2K+1)
    GF: np.ndarray | None = None  # (ncl, 2nf): contact forces from y (0 for an open clearance)
    HF: np.ndarray | None = None  # (ncl, 2K+1)
    compliant: np.ndarray | None = None  # bool per clearance: closed compliant (monitor = overlap)
    # closed Hertz contacts (nonlinear, scipy only): their clearances, their forces' effect on y' and on
    # the contact forces, per unit force
    hertz: np.ndarray | None = None  # clearance indices
    hertz_rate: np.ndarray | None = None  # (2nf, nh)
    hertz_force: np.ndarray | None = None  # (ncl, nh)
    cache: dict = field(default_factory=dict, repr=False)  # per-back-end derived data

    @property
    def size(self) -> int:
        return self.A.shape[0]

    @property
    def n_harmonics(self) -> int:
        return (self.B.shape[1] - 1) // 2

    def basis(self, t: float | np.ndarray) -> np.ndarray:
        """u(t): a vector (2K+1,), or columns (2K+1, nt) for an array of t."""
        return fourier_basis(self.omega, self.n_harmonics, t)

    def basis_rate(self, t: float | np.ndarray) -> np.ndarray:
        """u'(t), shaped as :meth:`basis`."""
        return fourier_basis(self.omega, self.n_harmonics, t, rate=True)

    def forcing(self, t: float) -> np.ndarray:
        return self.B @ self.basis(t)

    def particular(self, t: float | np.ndarray) -> np.ndarray:
        """y_p at t (a vector), or at every t of an array (columns)."""
        return self.Y @ self.basis(t)

    def harmonic(self, coefficients: np.ndarray, t: float | np.ndarray) -> np.ndarray:
        return coefficients @ self.basis(t)


def fourier_basis(omega: float, harmonics: int, t: float | np.ndarray, rate: bool = False) -> np.ndarray:
    """(1, cos kωt.., sin kωt..) for k = 1..K at t, or its time derivative."""
    if harmonics == 1 and isinstance(t, float):  # the thesis cam at one instant: the common case
        cos, sin = math.cos(omega * t), math.sin(omega * t)
        return np.array([0.0, -omega * sin, omega * cos] if rate else [1.0, cos, sin])
    t = np.asarray(t, dtype=float)
    k_omega = omega * np.arange(1, harmonics + 1)
    phase = np.multiply.outer(k_omega, t)
    out = np.empty((1 + 2 * harmonics,) + t.shape)  # filled in place: a block's basis is a few calls, not ten
    if rate:
        kw = k_omega.reshape((-1,) + (1,) * t.ndim)
        out[0] = 0.0
        np.multiply(np.sin(phase), -kw, out=out[1:harmonics + 1])
        np.multiply(kw, np.cos(phase), out=out[harmonics + 1:])
        return out
    out[0] = 1.0
    np.cos(phase, out=out[1:harmonics + 1])
    np.sin(phase, out=out[harmonics + 1:])
    return out


def shift_coefficients(coefficients: np.ndarray, omega: float, harmonics: int, t: float) -> np.ndarray:
    """C' with C' u(τ) = C u(t + τ) (the angle-addition formulas, harmonic by harmonic)."""
    if harmonics == 1:  # the thesis cam: the same arithmetic on scalars, and one array made
        cos, sin = math.cos(omega * t), math.sin(omega * t)
        out = np.empty_like(coefficients)
        c_part, s_part = coefficients[:, 1], coefficients[:, 2]
        out[:, 0] = coefficients[:, 0]
        out[:, 1] = c_part * cos + s_part * sin
        out[:, 2] = s_part * cos - c_part * sin
        return out
    phase = omega * t * np.arange(1, harmonics + 1)
    cos, sin = np.cos(phase), np.sin(phase)
    c_part, s_part = coefficients[:, 1:harmonics + 1], coefficients[:, harmonics + 1:]
    return np.concatenate([coefficients[:, :1], c_part * cos + s_part * sin, s_part * cos - c_part * sin],
                          axis=1)


def state_space(mask: int, free: np.ndarray, pres: np.ndarray, pres_sources: np.ndarray,
                M: np.ndarray, C: np.ndarray, K: np.ndarray, series: SourceSeries,
                label: str = "") -> StateSpace:
    """State-space form of one configuration from its layer matrices (see module doc).

    ``free`` and ``pres`` are layer columns; ``pres_sources[p]`` is the row of
    ``series`` that moves prescribed column ``pres[p]``; ``label`` names the
    configuration in errors.
    """
    free = np.asarray(free, dtype=np.int64)
    pres = np.asarray(pres, dtype=np.int64)
    nf, n2, harmonics = free.size, 2 * free.size, series.n_harmonics
    omega = float(series.omega)
    width = 2 * harmonics + 1
    A, B, Y = np.zeros((n2, n2)), np.zeros((n2, width)), np.zeros((n2, width))
    if nf == 0:
        return StateSpace(mask, free, A, B, Y, omega, 0.0)
    ff = np.ix_(free, free)
    fp = np.ix_(free, pres)
    Mff, Cff, Kff = M[ff], C[ff], K[ff]
    Mfp, Cfp, Kfp = M[fp], C[fp], K[fp]
    A[:nf, nf:] = np.eye(nf)
    A[nf:] = -np.linalg.solve(Mff, np.hstack([Kff, Cff]))
    rows = np.asarray(pres_sources, dtype=np.int64)
    # constant part: K_FF X0 = -K_FP c
    load = -Kfp @ series.const[rows]
    B[nf:, 0] = np.linalg.solve(Mff, load)
    Y[:nf, 0] = _static(Kff, load, label)
    # harmonics: complex amplitudes X_P = a - i b
    for k in range(harmonics):
        amplitude = series.cos[rows, k] - 1j * series.sin[rows, k]
        if not amplitude.any():
            continue
        w = (k + 1) * omega
        force = -(Kfp - w * w * Mfp + 1j * w * Cfp) @ amplitude
        try:
            X = np.linalg.solve(Kff - w * w * Mff + 1j * w * Cff, force)
        except np.linalg.LinAlgError:
            raise RunError(f"harmonic {k + 1} of the cam speed is exactly a natural frequency of "
                           f"configuration {label} (undamped resonance)") from None
        Z = np.concatenate([X, 1j * w * X])
        Bz = np.linalg.solve(Mff, force)
        B[nf:, 1 + k], B[nf:, 1 + harmonics + k] = Bz.real, -Bz.imag
        Y[:, 1 + k], Y[:, 1 + harmonics + k] = Z.real, -Z.imag
    omega_max = float(np.abs(np.linalg.eigvals(A)).max())
    T, Tinv = _balance(Mff, Kff)
    return StateSpace(mask, free, A, B, Y, omega, omega_max, T, Tinv)


def _balance(M: np.ndarray, K: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """T, T⁻¹ with z = T y = (S Φᵀ M x, Φᵀ M v): modal energy coordinates.

    Φ are the mass-normalised undamped modes (K Φ = M Φ Ω², Φᵀ M Φ = I) and
    S = diag(ω_i) (rigid-body modes take the lowest positive ω). In z, A is
    skew-symmetric plus the modal damping, nearly normal: its eigenvectors are
    well conditioned however wide the range of frequencies.
    """
    nf = M.shape[0]
    w2, Phi = scipy.linalg.eigh(K, M)
    positive = w2[w2 > 1e-12 * max(float(w2.max()), 0.0)]
    s = np.sqrt(np.maximum(w2, positive.min() if positive.size else 1.0))
    PhiM = Phi.T @ M
    T, Tinv = np.zeros((2 * nf, 2 * nf)), np.zeros((2 * nf, 2 * nf))
    T[:nf, :nf], T[nf:, nf:] = s[:, None] * PhiM, PhiM
    Tinv[:nf, :nf], Tinv[nf:, nf:] = Phi / s, Phi
    return T, Tinv


def _static(K: np.ndarray, load: np.ndarray, label: str) -> np.ndarray:
    """X with K X = load: a direct solve, or on the range of a singular K (SVD)."""
    scale = float(np.abs(load).max())
    if scale == 0.0:
        return np.zeros(load.size)
    U, s, Vt = np.linalg.svd(K)
    rank = int((s > s[0] * K.shape[0] * np.finfo(float).eps).sum()) if s.size and s[0] > 0 else 0
    if rank == K.shape[0]:
        return scipy.linalg.solve(K, load, check_finite=False)
    on_null = U[:, rank:].T @ load
    if np.abs(on_null).max() > 1e-9 * scale:
        raise RunError(f"configuration {label} has no steady solution under a constant load "
                       "(a free rigid-body motion is loaded)")
    return Vt[:rank].T @ ((U[:, :rank].T @ load) / s[:rank])


class Propagator:
    """e^{Aτ} applied to homogeneous states, in modal or plain coordinates (see module doc).

    A state is carried as h: modal coordinates w = V⁻¹ y_h (complex) when A
    is diagonalised, y_h itself otherwise; :attr:`V` maps h back (y_h = Re V h).
    The eigendecomposition is taken of T A T⁻¹ in the balanced coordinates
    z = T y (:func:`_balance`) when T is given: A itself has eigenvectors with
    condition numbers of 1e6 to 1e10 (x and v differ by the frequencies).

    An undamped free rigid-body mode makes A defective (a Jordan block at 0).
    In balanced coordinates such a mode is a decoupled pair (z_x' = a z_v,
    z_v' = 0); it is kept as is, h_x(τ) = h_x + a τ h_v (the ``drift``), and
    the rest is diagonalised. Only if that fails too is expm used.
    """

    def __init__(self, A: np.ndarray, step: float, T: np.ndarray | None = None,
                 Tinv: np.ndarray | None = None) -> None:
        self.A = A
        self.step = step
        self.modal = False
        n = A.shape[0]
        self.drift_x = self.drift_v = np.zeros(0, dtype=np.int64)
        self.drift = np.zeros(0)
        self._powers: np.ndarray | None = None
        self._real_powers = np.zeros((0, 0))
        if n:
            balanced = T is not None and Tinv is not None
            Az = T @ A @ Tinv if balanced else A
            decomposed = _diagonalise(Az, *(_rigid_pairs(Az) if balanced else ([], [])))
            if decomposed is not None:
                self.modal = True
                self.lam, W, Winv, self.drift_x, self.drift_v, self.drift = decomposed
                self.V, self.Vinv = (Tinv @ W, Winv @ T) if balanced else (W, Winv)
        if not self.modal:
            self.lam = np.zeros(n)
            self.V = np.eye(n)
            self.Vinv = self.V
            self.step_matrix = scipy.linalg.expm(A * step) if n else np.zeros((0, 0))

    def to_h(self, yh: np.ndarray) -> np.ndarray:
        return self.Vinv @ yh if self.modal else yh

    def real(self, h: np.ndarray) -> np.ndarray:
        return (self.V @ h).real if self.modal else h

    def __call__(self, h: np.ndarray, taus: np.ndarray, uniform: bool = False) -> np.ndarray:
        """h at each τ of ``taus`` (columns); ``uniform``: taus = step * (1, 2, ...)."""
        taus = np.asarray(taus, dtype=float)
        if self.modal:
            if uniform:  # powers of e^{λ δ}: products, not exponentials (round-off grows as i eps)
                factors = np.empty((self.lam.size, taus.size), dtype=complex)
                factors[:] = np.exp(self.lam * self.step)[:, None]
                out = np.cumprod(factors, axis=1) * h[:, None]
            else:
                out = np.exp(np.multiply.outer(self.lam, taus)) * h[:, None]
            if self.drift.size:
                out[self.drift_x] += np.multiply.outer(self.drift * h[self.drift_v], taus)
            return out
        out = np.empty((h.size, taus.size))
        current = h
        for i, tau in enumerate(taus):
            current = self.step_matrix @ current if uniform else scipy.linalg.expm(self.A * tau) @ h
            out[:, i] = current
        return out

    def grid(self, h: np.ndarray, count: int, rows: np.ndarray) -> tuple[np.ndarray, Callable]:
        """Re(rows h(τ)) at τ = step * (1..count) (columns), and states(index) = h at those τ.

        In modal form the powers e^{λ step i} are computed once (exponentials, not
        products) and a block costs one matrix product.
        """
        if not self.modal:
            hs = self(h, self.step * np.arange(1, count + 1), uniform=True)
            return rows @ hs, lambda index: hs[:, index]
        if self._powers is None or self._powers.shape[1] < count:
            self._powers = np.exp(np.multiply.outer(self.lam, self.step * np.arange(1, max(count, 256) + 1)))
            # the same powers as real rows (Re p_j, -Im p_j) side by side, so that Re(rows h · powers) is
            # one real product with (rows h) read as its (re, im) pairs: half the arithmetic of the complex
            # product (1A, 1024 samples: 25 against 30 µs, timeit)
            self._real_powers = np.empty((2 * self.lam.size, self._powers.shape[1]))
            self._real_powers[0::2] = self._powers.real
            self._real_powers[1::2] = -self._powers.imag
        powers = self._powers
        values = (rows * h).view(float) @ self._real_powers[:, :count]
        drift = self.drift * h[self.drift_v]
        if drift.size:
            values += np.multiply.outer((rows[:, self.drift_x] @ drift).real, self.step * np.arange(1, count + 1))

        def states(index: int | slice) -> np.ndarray:
            out = (powers[:, index].T * h).T
            if drift.size:
                taus = self.step * (np.arange(count)[index] + 1)
                out[self.drift_x] += np.multiply.outer(drift, taus) if out.ndim == 2 else drift * taus
            return out

        return values, states

    def at(self, h: np.ndarray, tau: float) -> np.ndarray:
        """h at one τ."""
        if self.modal:
            out = np.exp(self.lam * tau) * h
            if self.drift.size:
                out[self.drift_x] += self.drift * h[self.drift_v] * tau
            return out
        return scipy.linalg.expm(self.A * tau) @ h


def _rigid_pairs(Az: np.ndarray) -> tuple[list[int], list[int]]:
    """(x, v) indices of decoupled undamped rigid-body pairs of a balanced A (see Propagator)."""
    nf = Az.shape[0] // 2
    tiny = 1e-12 * float(np.abs(Az).max())
    xs, vs = [], []
    for j in range(nf):
        others = np.ones(2 * nf, bool)
        others[[j, nf + j]] = False
        if (np.abs(Az[nf + j]).max() <= tiny and np.abs(Az[:, j]).max() <= tiny
                and np.abs(Az[j, others]).max() <= tiny and np.abs(Az[others, nf + j]).max() <= tiny):
            xs.append(j)
            vs.append(nf + j)
    return xs, vs


def _diagonalise(Az: np.ndarray, xs: list[int], vs: list[int]):  # noqa: ANN202
    """(λ, W, W⁻¹, drift x, drift v, drift rate) with Az = W (Λ + N) W⁻¹, or None if ill-conditioned."""
    n = Az.shape[0]
    kept = np.setdiff1d(np.arange(n), xs + vs)
    lam = np.zeros(n, dtype=complex)
    W = np.zeros((n, n), dtype=complex)
    W[xs + vs, xs + vs] = 1.0
    if kept.size:
        values, vectors = np.linalg.eig(Az[np.ix_(kept, kept)])
        vectors = vectors / np.linalg.norm(vectors, axis=0)
        condition = np.linalg.cond(vectors)
        if not (np.isfinite(condition) and condition < MODAL_CONDITION_LIMIT):
            return None
        lam[kept] = values
        W[np.ix_(kept, kept)] = vectors
    drift = np.array([Az[x, v] for x, v in zip(xs, vs, strict=True)])
    return lam, W, np.linalg.inv(W), np.array(xs, dtype=np.int64), np.array(vs, dtype=np.int64), drift


def from_layer(problem, layer) -> StateSpace:  # noqa: ANN001 (a ContactProblem and its OrderedLayer)
    """State space of one configuration from the contact problem's ordered layer (free first).

    The sources' pull through closed compliant contacts (``layer.S``, on the
    sources' x, v, a) enters as one more prescribed column per source, with
    those couplings as its K, C and M entries.
    """
    nf, m = layer.nf, layer.m
    M, C, K, source = layer.M, layer.C, layer.K, layer.source
    ns = layer.S.shape[1] // 3
    if layer.S[:nf].any():
        size = m + ns
        M, C, K = (np.pad(X, ((0, ns), (0, ns))) for X in (M, C, K))
        for s in range(ns):
            K[:m, m + s], C[:m, m + s], M[:m, m + s] = layer.S[:, 3 * s], layer.S[:, 3 * s + 1], layer.S[:, 3 * s + 2]
        source = np.concatenate([source, np.arange(ns)])
        m = size
    return state_space(layer.mask, np.arange(nf), np.arange(nf, m), source, M, C, K,
                       problem.series, problem.label(layer.mask))
