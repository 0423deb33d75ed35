"""Centre response of a reduced model to a step load: RK4 and exact modal integration.

Equation of motion of the reduced model from rest (thesis eqs. 37, 38, 43)::

    M_R q̈ + K_R q = F H(t),   q(0) = q̇(0) = 0,   so   q̈ = M_R⁻¹ (F − K_R q)

Two back ends:

``rk4``
    The classical fourth-order Runge–Kutta method on y = (q, q̇) with step
    h = (ω_max h) / ω_max, ω_max the largest frequency of the reduced model.
    It is stable for ω_max h < 2√2 ≈ 2.83 (the thesis' 2.8), adequate near 1.
    For this linear, constant-coefficient system the RK4 step is the matrix
    polynomial y ← R y + r with R = I + hL + (hL)²/2 + (hL)³/6 + (hL)⁴/24,
    L = [[0, I], [−M⁻¹K, 0]]: the same iterates as the four-stage form
    (:func:`rk4_reference`), one matrix-vector product per step.
``modal``
    Exact integration of the reduced model through its own modes
    (K_R φ = ω² M_R φ, mass-normalized): q = Σ φ (φᵀF/ω²)(1 − cos ωt). No
    step limit; it is the h → 0 limit of ``rk4``.

Results are non-dimensional as in the thesis: time t/T (T the exact
fundamental period), displacement w/(p0/(ρh ω₁₁²)), velocity
ẇ/(p0/(ρh ω₁₁)), acceleration ẅ/(p0/ρh). A point force P is measured by its
mean pressure p0 = P/(ab).

Peak error (thesis, Figs. 9 and 10): the percentage error (eq. 40) of the
largest positive or negative value of a history, whichever is larger in
magnitude in the exact history, against the approximate extreme of the
same sign. (Read as "the larger of the errors of the positive and the
negative extremes" the velocity under a uniform load would be judged on
its smaller, later negative swing; the thesis' ~2 % velocity error of the
full model at ω_max h = 1 matches the reading used here.)
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
import scipy.linalg as sla

from vtool.assessments.cancel import Cancel, check
from vtool.assessments.plate.assembly import Plate
from vtool.assessments.plate.exact import ExactResponse, lowest_modes, step_histories, step_response
from vtool.assessments.plate.model import ReducedModel
from vtool.errors import InputError

LOADS = ("uniform", "point")
SCHEMES = ("rk4", "modal")
#: RK4 is stable on the imaginary axis up to |z| = 2√2.
RK4_STABILITY_LIMIT = 2.0 * np.sqrt(2.0)
#: The thesis' rounded limit (eq. 44); ω_max h above it is rejected.
RK4_LIMIT_THESIS = 2.8
#: Smallest ω_max h accepted (the thesis went down to 0.5).
MIN_OMEGA_MAX_H = 0.01
#: Cost guard of one RK4 run: steps x 2 KS stored values (8 bytes each: 400 MB).
MAX_RK4_VALUES = 5e7


@dataclass(frozen=True)
class Scales:
    """Non-dimensionalizing scales (SI or consistent inch units)."""

    period: float  # T = 2π/ω₁₁ (exact)
    displacement: float  # p0 / (ρh ω₁₁²)
    velocity: float  # p0 / (ρh ω₁₁)
    acceleration: float  # p0 / ρh
    load: float  # the load amplitude used: p0 (uniform) or P = p0 ab (point)


def scales(plate: Plate, load: str, p0: float = 1.0) -> Scales:
    omega = lowest_modes(plate, 1)[0].omega
    m = plate.mass_per_area
    amplitude = p0 if load == "uniform" else p0 * plate.a * plate.b
    return Scales(2 * np.pi / omega, p0 / (m * omega**2), p0 / (m * omega), p0 / m, amplitude)


@dataclass(frozen=True)
class Response:
    """Non-dimensional centre histories of one run and what it cost."""

    case: str
    size: int
    load: str
    scheme: str
    omega_max_h: float  # NaN for the modal back end
    step: float  # h in seconds (NaN for modal)
    steps: int
    tau: np.ndarray  # t / T
    displacement: np.ndarray
    velocity: np.ndarray
    acceleration: np.ndarray
    seconds: float  # set-up (ω_max, factorization, propagator) and time loop
    operations: float  # multiply-adds of the time loop (RK4: steps × (2 KS)²)
    loop_seconds: float  # the time loop (or the modal sums) alone


def _load_vector(model: ReducedModel, load: str, s: Scales) -> np.ndarray:
    if load == "uniform":
        return s.load * model.f_uniform
    if load == "point":
        return s.load * model.f_point
    raise ValueError(f"load: {load!r} is not one of: {', '.join(LOADS)}")


def omega_max(model: ReducedModel) -> float:
    lam = sla.eigh(model.K, model.M, eigvals_only=True)
    return float(np.sqrt(lam[-1]))


def rk4_propagator(A: np.ndarray, g: np.ndarray, h: float) -> tuple[np.ndarray, np.ndarray]:
    """(R, r) with y_{n+1} = R y_n + r for one RK4 step of q̈ = g − A q, y = (q, q̇)."""
    n = A.shape[0]
    L = np.zeros((2 * n, 2 * n))
    L[:n, n:] = np.eye(n)
    L[n:, :n] = -A
    c = np.concatenate([np.zeros(n), g])
    hL = h * L
    hL2 = hL @ hL
    hL3 = hL2 @ hL
    eye = np.eye(2 * n)
    R = eye + hL + hL2 / 2 + hL3 / 6 + hL3 @ hL / 24
    r = h * (eye + hL / 2 + hL2 / 6 + hL3 / 24) @ c
    return R, r


def rk4_reference(A: np.ndarray, g: np.ndarray, h: float, steps: int) -> np.ndarray:
    """Textbook four-stage RK4 for q̈ = g − A q from rest; returns q at every step (tests)."""
    n = A.shape[0]

    def f(y: np.ndarray) -> np.ndarray:
        return np.concatenate([y[n:], g - A @ y[:n]])

    y = np.zeros(2 * n)
    out = np.zeros((steps + 1, n))
    for k in range(steps):
        k1 = f(y)
        k2 = f(y + h / 2 * k1)
        k3 = f(y + h / 2 * k2)
        k4 = f(y + h * k3)
        y = y + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        out[k + 1] = y[:n]
    return out


def run_rk4(plate: Plate, model: ReducedModel, load: str, omega_max_h: float,
            periods: float = 1.5, cancel: Cancel | None = None) -> Response:
    """RK4 from rest at the given ω_max·h over ``periods`` exact fundamental periods."""
    if not (math.isfinite(omega_max_h) and MIN_OMEGA_MAX_H <= omega_max_h <= RK4_LIMIT_THESIS):
        raise InputError("omega_max_h", omega_max_h,
                         f"in [{MIN_OMEGA_MAX_H:g}, {RK4_LIMIT_THESIS:g}] (RK4 stability; smaller "
                         "steps buy nothing the modal back end does not give exactly)")
    s = scales(plate, load)
    F = _load_vector(model, load, s)
    start = time.perf_counter()
    w_max = omega_max(model)
    h = omega_max_h / w_max
    steps_f = periods * s.period / h
    cost = steps_f * 2 * model.size
    if not (math.isfinite(steps_f) and cost <= MAX_RK4_VALUES):
        raise InputError("transient", f"{steps_f:.3g} RK4 steps x {2 * model.size} states",
                         f"<= {MAX_RK4_VALUES:.0e} stored values (fewer periods, a larger "
                         "omega_max_h, or the modal back end)")
    check(cancel)
    steps = int(np.ceil(steps_f))
    cho = sla.cho_factor(model.M)
    A = sla.cho_solve(cho, model.K)
    g = sla.cho_solve(cho, F)
    R, r = rk4_propagator(A, g, h)
    n = model.size
    Y = np.zeros((steps + 1, 2 * n))
    y = np.zeros(2 * n)
    loop_start = time.perf_counter()
    for k in range(steps):
        y = R @ y + r
        Y[k + 1] = y
        if k % 4096 == 4095:
            check(cancel)
    loop_seconds = time.perf_counter() - loop_start
    q, v = Y[:, :n], Y[:, n:]
    acc = g[None, :] - q @ A.T
    c = model.centre_row
    seconds = time.perf_counter() - start
    t = np.arange(steps + 1) * h
    return Response(
        model.case.name, n, load, "rk4", omega_max_h, h, steps, t / s.period,
        (q @ c) / s.displacement, (v @ c) / s.velocity, (acc @ c) / s.acceleration,
        seconds, float(steps) * (2 * n) ** 2, loop_seconds,
    )


def run_modal(plate: Plate, model: ReducedModel, load: str, tau: np.ndarray) -> Response:
    """Exact modal integration of the reduced model at times ``tau`` (= t/T)."""
    s = scales(plate, load)
    F = _load_vector(model, load, s)
    start = time.perf_counter()
    lam, Phi = sla.eigh(model.K, model.M)
    omega = np.sqrt(np.clip(lam, 0.0, None))
    coeff = (model.centre_row @ Phi) * (Phi.T @ F)  # centre reading of each mode × modal force
    t = np.asarray(tau, dtype=float) * s.period
    wt = np.outer(t, omega)
    cos = np.cos(wt)
    disp = (1.0 - cos) @ (coeff / omega**2)
    vel = np.sin(wt) @ (coeff / omega)
    acc = cos @ coeff
    seconds = time.perf_counter() - start
    return Response(
        model.case.name, model.size, load, "modal", float("nan"), float("nan"), t.size,
        np.asarray(tau, dtype=float), disp / s.displacement, vel / s.velocity,
        acc / s.acceleration, seconds, float(t.size) * model.size, seconds,
    )


@dataclass(frozen=True)
class ExactHistories:
    """Exact (Navier) non-dimensional centre histories and their mode-count convergence."""

    load: str
    tau: np.ndarray
    displacement: np.ndarray
    velocity: np.ndarray
    acceleration: np.ndarray
    n_modes: int
    change_pct: dict[str, float]  # change of the peak when the modes are halved, %
    acceleration_converged: bool
    #: quantity -> (largest, smallest) value of the exact series, refined between the samples
    extremes: dict[str, tuple[float, float]] = field(default_factory=dict, compare=False)

    @property
    def acceleration_defined(self) -> bool:
        """Whether the acceleration has an exact value to compare with at all: the uniform pressure's
        series (converged or not, see ``acceleration_converged``), not the point force's, which diverges."""
        return self.load == "uniform"

    def extreme(self, name: str, sign: str) -> float:
        """The largest (``+``) or smallest (``-``) value of history ``name``: refined when known, else sampled."""
        values = getattr(self, name)
        sampled = float(np.max(values)) if sign == "+" else float(np.min(values))
        if name not in self.extremes:
            return sampled
        refined = self.extremes[name][0 if sign == "+" else 1]
        return max(sampled, refined) if sign == "+" else min(sampled, refined)


def exact_samples(plate: Plate, periods: float, n_modes: int, samples_per_period: int = 40) -> int:
    """Time samples of :func:`exact_histories`: ``samples_per_period`` per period of the top mode."""
    top = lowest_modes(plate, n_modes)[-1].omega
    w11 = lowest_modes(plate, 1)[0].omega
    return int(np.ceil(periods * samples_per_period * top / w11)) + 1


def exact_histories(plate: Plate, load: str, periods: float = 1.5, n_modes: int = 200,
                    samples_per_period: int = 40, tau: np.ndarray | None = None) -> ExactHistories:
    """The exact reference on a grid fine enough for its highest mode (or on ``tau``)."""
    s = scales(plate, load)
    if tau is None:
        tau = np.linspace(0.0, periods, exact_samples(plate, periods, n_modes, samples_per_period))
    r: ExactResponse = step_response(plate, load, tau * s.period, n_modes)
    histories = (s.load * r.displacement / s.displacement, s.load * r.velocity / s.velocity,
                 s.load * r.acceleration / s.acceleration)
    evaluate = step_histories(plate, load, n_modes)
    extremes = {}
    for index, name in enumerate(QUANTITIES):
        scale = s.load / (s.displacement, s.velocity, s.acceleration)[index]

        def value(t: float, index: int = index, scale: float = scale) -> float:
            return float(evaluate(t * s.period)[index][0]) * scale

        extremes[name] = (refine_extreme(value, tau, histories[index], +1.0),
                          refine_extreme(value, tau, histories[index], -1.0))
    return ExactHistories(
        load, tau, *histories, n_modes,
        {"displacement": 100 * r.change_displacement, "velocity": 100 * r.change_velocity,
         "acceleration": 100 * r.change_acceleration},
        r.acceleration_converged, extremes,
    )


def refine_extreme(value: Callable[[float], float], tau: np.ndarray, samples: np.ndarray, sign: float) -> float:
    """The largest (``sign`` +1) or smallest (-1) value of the exact series near its extreme sample.

    The exact history is known at every instant, so its peak is not the
    largest sample: a bounded Brent search between the samples either side of
    the extreme sample (within the window) finds it; never less extreme than
    that sample.
    """
    from scipy.optimize import minimize_scalar

    k = int(np.argmax(sign * samples))
    best = float(samples[k])
    low, high = float(tau[max(k - 1, 0)]), float(tau[min(k + 1, tau.size - 1)])
    if high <= low:
        return best
    found = minimize_scalar(lambda t: -sign * value(t), bounds=(low, high), method="bounded",
                            options={"xatol": 1e-12 * max(abs(high), 1.0)})
    return max(best, -float(found.fun)) if sign > 0 else min(best, float(found.fun))


#: A negative (positive) peak smaller than this fraction of the largest |value|
#: is not reported: the history hardly swings to that side.
SIGNED_PEAK_FLOOR = 0.05
SIGNS = ("+", "-")


def signed_peak_error_pct(approx: np.ndarray, exact: np.ndarray, sign: str, refined: float | None = None) -> float:
    """Percentage error (eq. 40) of the largest positive (``+``) or negative (``-``) value.

    NaN when the exact history's extreme of that sign is below
    :data:`SIGNED_PEAK_FLOOR` of its largest magnitude. ``refined``: the exact
    extreme of that sign found between the samples (:func:`refine_extreme`).
    """
    e = float(np.max(exact)) if sign == "+" else float(np.min(exact))
    if refined is not None:
        e = refined
    scale = max(float(np.max(np.abs(exact))), abs(e))
    if scale == 0.0 or abs(e) < SIGNED_PEAK_FLOOR * scale or (e > 0) != (sign == "+"):
        return float("nan")
    a = float(np.max(approx)) if sign == "+" else float(np.min(approx))
    return (a - e) / e * 100.0


def peak_at_end(exact: np.ndarray, tau: np.ndarray, margin: float = 0.02,
                near: float = 0.95) -> bool:
    """True when the window may cut the history's peak short.

    Either the largest |value| lies in the last ``margin`` periods, or |value|
    is still rising at the end and already within ``near`` of the largest:
    the true peak may lie just past the window (the point-load deflection
    of the 40:27 plate peaks at t/T = 1.517, past a 1.5-period window).
    """
    mag = np.abs(exact)
    k = int(np.argmax(mag))
    if tau[k] >= tau[-1] - margin:
        return True
    return bool(mag.size > 1 and mag[-1] > mag[-2] and mag[-1] >= near * mag[k])


def peak_error_pct(approx: np.ndarray, exact: np.ndarray, refined: tuple[float, float] | None = None) -> float:
    """Signed percentage error of the peak (see module docstring); ``refined``: the exact history's
    (largest, smallest) value found between its samples (:func:`refine_extreme`)."""
    k = int(np.argmax(np.abs(exact)))
    e = float(exact[k])
    if refined is not None:
        e = refined[0] if e > 0 else refined[1]
    if e == 0.0:
        return 0.0
    a = float(np.max(approx)) if e > 0 else float(np.min(approx))
    return (a - e) / e * 100.0  # eq. 40: positive when the approximate peak is larger in magnitude


QUANTITIES = ("displacement", "velocity", "acceleration")


def peak_errors(resp: Response, exact: ExactHistories) -> dict[str, float]:
    """Peak errors of displacement, velocity and acceleration against the exact reference.

    The point-load acceleration has no exact value (its series diverges): NaN. The uniform-load
    acceleration is compared with its series at the exact reference's modes, as the thesis does, though
    that is not converged (``acceleration_converged``; the report says so).
    """
    out = {}
    for name in QUANTITIES:
        if name == "acceleration" and not exact.acceleration_defined:
            out[name] = float("nan")
            continue
        out[name] = peak_error_pct(getattr(resp, name), getattr(exact, name), exact.extremes.get(name))
    return out


def signed_peak_errors(resp: Response, exact: ExactHistories) -> dict[str, float]:
    """Errors of the positive and negative peaks: keys ``displacement+``, ``displacement-``, ..."""
    out = {}
    for name in QUANTITIES:
        for sign in SIGNS:
            if name == "acceleration" and not exact.acceleration_defined:
                out[name + sign] = float("nan")
            else:
                refined = exact.extremes[name][SIGNS.index(sign)] if name in exact.extremes else None
                out[name + sign] = signed_peak_error_pct(getattr(resp, name), getattr(exact, name), sign, refined)
    return out


def halving_change_pct(plate: Plate, model: ReducedModel, load: str, omega_max_h: float,
                       periods: float = 1.5, cancel: Cancel | None = None) -> dict[str, float]:
    """The thesis' accuracy check: rerun with h/2, largest change as % of each peak."""
    coarse = run_rk4(plate, model, load, omega_max_h, periods, cancel)
    fine = run_rk4(plate, model, load, max(omega_max_h / 2.0, MIN_OMEGA_MAX_H), periods, cancel)
    out = {}
    for name in QUANTITIES:
        a = getattr(coarse, name)
        b = np.interp(coarse.tau, fine.tau, getattr(fine, name))
        out[name] = float(np.max(np.abs(a - b)) / np.max(np.abs(b)) * 100.0)
    return out
