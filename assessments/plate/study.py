"""The thesis' Tables 2–5 regenerated: every case, its KS, errors and cost.

* Tables 2 and 3: lowest frequencies of each case against the exact ones
  (percentage errors, eq. 40) and ω_max/ω₁₁ (eq. 42), per element.
* Mesh convergence of the unreduced models (fundamental error against
  element size, observed order from a log-log fit).
* Table 4: cost against KS: eigenproblem time (with the fitted exponent,
  the thesis found KS^2.5) and RK4 time, steps and operation count
  (steps × (2 KS)², the thesis' KS²/h).
* Table 5: transient peak errors of each transient case, load and ω_max h
  against the exact reference, the reduced model's own exact (modal)
  result, the halving-h check, and the cheapest acceptable combination:
  |error| ≤ |error of the full model, modal| + tolerance, with the
  halving-h change within the tolerance.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from vtool.assessments.cancel import Cancel, check
from vtool.assessments.plate.assembly import Plate
from vtool.assessments.plate.elements import ELEMENTS
from vtool.assessments.plate.model import Case, MasterSelection, ReducedModel, build_model
from vtool.assessments.plate.transient import (
    LOADS,
    MIN_OMEGA_MAX_H,
    QUANTITIES,
    RK4_LIMIT_THESIS,
    SCHEMES,
    ExactHistories,
    Response,
    exact_histories,
    exact_samples,
    halving_change_pct,
    peak_at_end,
    peak_errors,
    run_modal,
    run_rk4,
    signed_peak_errors,
)
from vtool.assessments.plate.vibration import FreeVibration, convergence_order, free_vibration
from vtool.errors import InputError
from vtool.threads import limited

#: Transient window in exact fundamental periods: 2 holds the exact peak of
#: every load case of the 40:27 plate (the point-load displacement peaks at
#: t/T = 1.517, just past the thesis-like 1.5); :func:`window_warnings` checks.
DEFAULT_PERIODS = 2.0
MAX_EXACT_MODES = 1000
#: Largest degree-of-freedom count of one model (dense M and K, eigh): 1500
#: DOF is 18 MB per matrix and about a second of eigenproblem.
MAX_DOF = 1500
#: Cost guard of the exact reference: time samples x modes (blocked, so time).
MAX_EXACT_VALUES = 1e8


def mesh_dofs(element: str, nx: int, ny: int) -> int:
    """DOF of an unconstrained nx x ny mesh (an upper bound of the model size)."""
    return (nx + 1) * (ny + 1) * ELEMENTS[element].dofs_per_node


def check_mesh_size(element: str, nx: int, ny: int, field: str = "mesh") -> int:
    """Refuse a mesh above :data:`MAX_DOF` before any matrix exists; returns its DOF count."""
    dofs = mesh_dofs(element, nx, ny)
    if dofs > MAX_DOF:
        mb = dofs * dofs * 8 / 1e6
        raise InputError(field, f"{nx}x{ny} {element} = {dofs} DOF (~{mb:.0f} MB per matrix)",
                         f"at most {MAX_DOF} DOF (a coarser mesh)")
    return dofs


@dataclass(frozen=True)
class TransientSettings:
    """Which cases get transient runs, with which loads and steps.

    ``truncation_check``: also evaluate the exact reference with
    ``4 x exact_modes`` modes (on the same time grid) and report the errors
    against it beside the ``exact_modes`` ones.
    """

    cases: tuple[str, ...] = ()
    loads: tuple[str, ...] = ("uniform", "point")
    omega_max_h: tuple[float, ...] = (2.0, 1.0, 0.5)
    periods: float = DEFAULT_PERIODS
    exact_modes: int = 200
    tolerance_pct: float = 2.0
    truncation_check: bool = True


def check_exact_cost(plate: Plate, settings: TransientSettings, field: str = "transient") -> float:
    """Refuse an exact reference above :data:`MAX_EXACT_VALUES` (time samples x modes)."""
    if not settings.cases:
        return 0.0
    samples = exact_samples(plate, settings.periods, settings.exact_modes)
    modes = settings.exact_modes * (5 if settings.truncation_check else 1)  # N and 4N
    cost = float(samples) * modes * 2  # the halved-mode convergence check doubles it
    if cost > MAX_EXACT_VALUES:
        raise InputError(field, f"{samples} samples x {modes} modes = {cost:.3g} values",
                         f"<= {MAX_EXACT_VALUES:.0e} (fewer exact_modes or periods, or "
                         "truncation_check = false)")
    return cost


@dataclass(frozen=True)
class Study:
    """A plate and its cases; what ``vtool plate study`` runs."""

    plate: Plate
    cases: tuple[Case, ...]
    frequencies: int = 6
    convergence_meshes: tuple[int, ...] = (2, 4, 8)
    transient: TransientSettings = field(default_factory=TransientSettings)

    def case(self, name: str) -> Case:
        for c in self.cases:
            if c.name == name:
                return c
        raise KeyError(name)


@dataclass(frozen=True)
class ConvergenceRow:
    element: str
    n: int
    size: int
    fundamental_error_pct: float


@dataclass(frozen=True)
class TransientRow:
    """One run: peak errors (%) against the N-mode exact reference (``errors_pct``), its
    positive and negative peaks (``signed_pct``, keys ``displacement+`` ...), and the
    errors against the 4N-mode reference (``errors_4n_pct``, empty when not checked)."""

    case: str
    size: int
    load: str
    omega_max_h: float  # NaN: exact modal integration of the reduced model
    steps: int
    seconds: float  # RK4: the time loop alone; modal: the modal sums
    operations: float
    errors_pct: dict[str, float]
    halving_pct: dict[str, float] = field(default_factory=dict)
    signed_pct: dict[str, float] = field(default_factory=dict)
    errors_4n_pct: dict[str, float] = field(default_factory=dict)


@dataclass(frozen=True)
class Optimum:
    load: str
    quantity: str
    row: TransientRow | None
    limit_pct: float
    note: str = ""


@dataclass(frozen=True)
class StudyResult:
    study: Study
    free: list[FreeVibration]
    convergence: list[ConvergenceRow]
    orders: dict[str, float]
    eigen_exponent: float
    transient: list[TransientRow]
    exact: dict[str, ExactHistories]
    optima: list[Optimum]
    seconds: float
    exact_4n: dict[str, ExactHistories] = field(default_factory=dict)
    warnings: tuple[str, ...] = ()


def _eigen_time(model: ReducedModel, repeats: int = 5, budget: float = 0.02) -> float:
    """Best-of time of the eigenproblem (at least ``repeats`` runs and ``budget`` seconds)."""
    import scipy.linalg as sla

    best, spent, runs = math.inf, 0.0, 0
    while runs < repeats or (spent < budget and runs < 200):
        start = time.perf_counter()
        sla.eigh(model.K, model.M)
        elapsed = time.perf_counter() - start
        best, spent, runs = min(best, elapsed), spent + elapsed, runs + 1
    return best


def mesh_convergence(plate: Plate, elements: tuple[str, ...], meshes: tuple[int, ...]) -> tuple[list[ConvergenceRow], dict[str, float]]:
    """Fundamental error of unreduced n × n meshes and the observed order per element."""
    rows, orders = [], {}
    for element in elements:
        errs = []
        for n in meshes:
            model = build_model(plate, Case(f"{n}x{n}", element, n, n, MasterSelection(named="all")))
            err = free_vibration(plate, model, 1).fundamental_error_pct
            rows.append(ConvergenceRow(element, n, model.size, err))
            errs.append(err)
        if len(meshes) >= 2:
            orders[element] = convergence_order(1.0 / np.array(meshes, dtype=float), np.array(errs))
    return rows, orders


def run_transient_case(plate: Plate, model: ReducedModel, settings: TransientSettings,
                       exact: dict[str, ExactHistories],
                       exact_4n: dict[str, ExactHistories] | None = None,
                       cancel: Cancel | None = None) -> list[TransientRow]:
    rows = []
    exact_4n = exact_4n or {}

    def row(r: Response, wh: float, seconds: float, halving: dict[str, float]) -> TransientRow:
        ex = exact[r.load]
        fine = peak_errors(r, exact_4n[r.load]) if r.load in exact_4n else {}
        return TransientRow(model.case.name, model.size, r.load, wh, r.steps, seconds,
                            r.operations, peak_errors(r, ex), halving, signed_peak_errors(r, ex),
                            fine)

    for load in settings.loads:
        for wh in settings.omega_max_h:
            r = run_rk4(plate, model, load, wh, settings.periods, cancel)
            again = run_rk4(plate, model, load, wh, settings.periods, cancel)  # time the warm run too
            if again.loop_seconds < r.loop_seconds:
                r = again
            halving = halving_change_pct(plate, model, load, wh, settings.periods, cancel)
            rows.append(row(r, wh, r.loop_seconds, halving))
        check(cancel)
        mo = run_modal(plate, model, load, exact[load].tau)
        rows.append(row(mo, float("nan"), mo.seconds, {}))
    return rows


def window_warnings(exact: dict[str, ExactHistories], periods: float) -> list[str]:
    """A warning for every exact peak in the last 2 % of a period of the window."""
    out = []
    for load, ex in exact.items():
        for q in QUANTITIES:
            if q == "acceleration" and not ex.acceleration_defined:
                continue
            if peak_at_end(getattr(ex, q), ex.tau):
                k = int(np.argmax(np.abs(getattr(ex, q))))
                out.append(f"warning: the exact {load}-load {q} peak is at t/T = {ex.tau[k]:.3f}, "
                           f"the end of the {periods:g}-period window: its error may be cut short "
                           "(raise [transient] periods)")
    return out


def optima(rows: list[TransientRow], settings: TransientSettings, full_case: str) -> list[Optimum]:
    """Cheapest RK4 (case, ω_max h) per load and quantity that is acceptable.

    Acceptable: the peak error is within the full model's own (modal) error
    plus the tolerance, and halving h changes the history by no more than
    the tolerance (the thesis' check, which rejects a lucky coarse step).
    Cost is the operation count steps × (2 KS)².
    """
    out = []
    for load in settings.loads:
        for q in QUANTITIES:
            ref = [r for r in rows if r.case == full_case and r.load == load and math.isnan(r.omega_max_h)]
            if not ref or math.isnan(ref[0].errors_pct[q]):
                out.append(Optimum(load, q, None, float("nan"),
                                   "no converged exact value" if load == "point" and q == "acceleration"
                                   else "no full-model reference"))
                continue
            limit = abs(ref[0].errors_pct[q]) + settings.tolerance_pct
            ok = [r for r in rows if r.load == load and not math.isnan(r.omega_max_h)
                  and abs(r.errors_pct[q]) <= limit
                  and r.halving_pct.get(q, 0.0) <= settings.tolerance_pct]
            best = min(ok, key=lambda r: (r.operations, r.size)) if ok else None
            out.append(Optimum(load, q, best, limit, "" if best else "none acceptable"))
    return out


@limited()  # small dense matrices: one BLAS thread (vtool.threads)
def run_study(study: Study, *, transient: bool = True, cancel: Cancel | None = None) -> StudyResult:
    """Free vibration of every case, mesh convergence, cost and transient accuracy.

    ``cancel`` is polled between models and runs (:mod:`vtool.assessments.cancel`).
    """
    start = time.perf_counter()
    plate = study.plate
    models = {}
    for c in study.cases:
        check(cancel)
        models[c.name] = build_model(plate, c)
    free = [free_vibration(plate, m, study.frequencies) for m in models.values()]
    elements = tuple(dict.fromkeys(c.element for c in study.cases))
    conv, orders = mesh_convergence(plate, elements, study.convergence_meshes)
    times = {name: _eigen_time(m) for name, m in models.items()}
    free = [
        FreeVibration(f.case, f.size, f.omega, f.exact, f.errors_pct, f.omega_max_ratio, times[f.case])
        for f in free
    ]
    sizes = np.array([m.size for m in models.values()], dtype=float)
    secs = np.array([times[n] for n in models], dtype=float)
    big = sizes >= 5
    exponent = float(np.polyfit(np.log(sizes[big]), np.log(secs[big]), 1)[0]) if big.sum() >= 2 else float("nan")
    rows: list[TransientRow] = []
    exact: dict[str, ExactHistories] = {}
    settings = study.transient
    exact_4n: dict[str, ExactHistories] = {}
    warnings: list[str] = []
    if transient and settings.cases:
        check_exact_cost(plate, settings)
        for load in settings.loads:
            check(cancel)
            exact[load] = exact_histories(plate, load, settings.periods, settings.exact_modes)
            if settings.truncation_check:
                check(cancel)
                exact_4n[load] = exact_histories(plate, load, settings.periods,
                                                 4 * settings.exact_modes, tau=exact[load].tau)
        warnings = window_warnings(exact, settings.periods)
        for name in settings.cases:
            check(cancel)
            rows.extend(run_transient_case(plate, models[name], settings, exact, exact_4n, cancel))
    full = max(study.cases, key=lambda c: models[c.name].size if c.name in settings.cases else -1)
    opt = optima(rows, settings, full.name) if rows else []
    return StudyResult(study, free, conv, orders, exponent, rows, exact, opt,
                       time.perf_counter() - start, exact_4n, tuple(warnings))


@dataclass(frozen=True)
class CaseRun:
    """One case under one step load by one scheme, against the exact reference.

    What ``vtool plate transient`` prints and the TUI's Transient tab draws.
    """

    case: Case
    size: int
    response: Response
    exact: ExactHistories
    errors_pct: dict[str, float]
    signed_pct: dict[str, float]
    halving_pct: dict[str, float]
    omega_max_h: float
    warnings: tuple[str, ...] = ()


def check_run_options(load: str, scheme: str, omega_max_h: float, periods: float,
                      exact_modes: int, prefix: str = "") -> None:
    """The ranges of a single-case run (the CLI's options and the TUI's run fields)."""
    if load not in LOADS:
        raise InputError(f"{prefix}load", load, f"one of: {', '.join(LOADS)}")
    if scheme not in SCHEMES:
        raise InputError(f"{prefix}scheme", scheme, f"one of: {', '.join(SCHEMES)}")
    if isinstance(omega_max_h, bool) or not isinstance(omega_max_h, int | float) or not (
            MIN_OMEGA_MAX_H <= omega_max_h <= RK4_LIMIT_THESIS):
        raise InputError(f"{prefix}omega_max_h", omega_max_h,
                         f">= {MIN_OMEGA_MAX_H:g} and <= {RK4_LIMIT_THESIS} (omega_max*h, RK4 "
                         "stability limit, thesis eq. 44)")
    if isinstance(periods, bool) or not isinstance(periods, int | float) or not 0.5 <= periods <= 20.0:
        raise InputError(f"{prefix}periods", periods, ">= 0.5 and <= 20 (exact fundamental periods)")
    if isinstance(exact_modes, bool) or not isinstance(exact_modes, int) or not (
            2 <= exact_modes <= MAX_EXACT_MODES):
        raise InputError(f"{prefix}exact_modes", exact_modes, f"an integer >= 2 and <= {MAX_EXACT_MODES}")


@limited()  # small dense matrices: one BLAS thread (vtool.threads)
def run_case(plate: Plate, case: Case, load: str, scheme: str = "rk4", omega_max_h: float = 1.0,
             periods: float = DEFAULT_PERIODS, exact_modes: int = 200, *, halving: bool = True,
             cancel: Cancel | None = None) -> CaseRun:
    """Build ``case``, run it (RK4 at ``omega_max_h`` or modal) and compare with exact."""
    check_run_options(load, scheme, omega_max_h, periods, exact_modes)
    check_mesh_size(case.element, case.nx, case.ny)
    check_exact_cost(plate, TransientSettings(cases=(case.name,), periods=periods,
                                              exact_modes=exact_modes, truncation_check=False))
    model = build_model(plate, case)
    check(cancel)
    exact = exact_histories(plate, load, periods, exact_modes)
    check(cancel)
    if scheme == "rk4":
        resp = run_rk4(plate, model, load, omega_max_h, periods, cancel)
        change = halving_change_pct(plate, model, load, omega_max_h, periods, cancel) if halving else {}
    else:
        resp = run_modal(plate, model, load, exact.tau)
        change = {}
    return CaseRun(case, model.size, resp, exact, peak_errors(resp, exact),
                   signed_peak_errors(resp, exact), change,
                   omega_max_h if scheme == "rk4" else float("nan"),
                   tuple(window_warnings({load: exact}, periods)))
